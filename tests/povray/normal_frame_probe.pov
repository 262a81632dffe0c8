// tests/scenes/normal_frame_probe.pcsg written by hand in POV-Ray's own syntax: a normal
// pattern given before an object's rotations and non-uniform scale (it turns and squashes
// with the object) and after them (fixed in the world), and bumps with a vector
// turbulence. `pcsg verify tests/scenes/normal_frame_probe.pcsg --pov
// tests/povray/normal_frame_probe.pov` must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's rotz(a) rotx(b) scale(s) X is POV-Ray's
// scale s rotate x * b rotate z * a.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -5, 3>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.7>
  angle 50
}
light_source { <-4, -6, 10> color rgb 1 }
background { color rgb <0.2, 0.25, 0.35> }

#declare Rippled = texture { pigment { color rgb <0.8, 0.7, 0.35> }
                             normal { ripples 2 frequency 8 translate <0.2, 0, 0.3> }
                             finish { phong 0.7 phong_size 30 } }

plane { z, 0
  texture { pigment { color rgb <0.5, 0.55, 0.6> }
            normal { bumps 0.8 scale 0.4 turbulence <0.6, 0.2, 0.1> } }
}
sphere { 0, 1 texture { Rippled }
  scale <1.1, 0.45, 0.8> rotate x * 60 rotate z * 40 translate <-1.1, 0, 0.9>
}
sphere { 0, 1
  scale <1.1, 0.45, 0.8> rotate x * 60 rotate z * 40 translate <1.2, 0, 0.9>
  texture { Rippled }
}
