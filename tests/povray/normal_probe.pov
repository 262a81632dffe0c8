// tests/scenes/normal_probe.pcsg written by hand in POV-Ray's own syntax: bumps, dents,
// wrinkles with turbulence, ripples and waves (POV-Ray's wave sources), a pattern moved with
// its object and one scaled non-uniformly and rotated.
// `pcsg verify tests/scenes/normal_probe.pcsg --pov tests/povray/normal_probe.pov` must
// agree: the tracer's perturbations against POV-Ray's own, not against the exporter's text.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0, its torus
// lies in the xy-plane. A texture written after an object's transformations lies in the
// scene's frame (a paint outside them); one written before them moves with the object.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -7, 3.2>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.7>
  angle 42
}
light_source { <-6, -12, 14> color rgb 1 }
light_source { <8, -4, 6> color rgb <0.35, 0.35, 0.45> }
background { color rgb <0.25, 0.35, 0.55> }

plane { z, 0
  texture { pigment { color rgb <0.6, 0.6, 0.65> }
            normal { bumps 1.2 scale 0.3 }
            finish { ambient 0.1 diffuse 0.7 } }
}
sphere { <-1.6, 0, 0.7>, 0.7
  texture { pigment { color rgb <0.8, 0.35, 0.25> }
            normal { dents 3 scale 0.25 }
            finish { diffuse 0.7 phong 0.6 phong_size 40 } }
}
sphere { <0, 0.6, 0.8>, 0.8
  texture { pigment { color rgb <0.85, 0.75, 0.4> }
            normal { wrinkles 1.2 scale 0.3 turbulence 0.3 }
            finish { diffuse 0.7 specular 0.5 roughness 0.02 } }
}
sphere { <0, 0, 0>, 0.7
  texture { pigment { color rgb <0.3, 0.5, 0.8> }
            normal { ripples 1 frequency 6 }
            finish { diffuse 0.6 phong 0.8 phong_size 60 } }
  translate <1.7, 0, 0.7>
}
torus { 0.6, 0.25 rotate x * 90 translate <0, -1.6, 0.3>
  texture { pigment { color rgb <0.5, 0.8, 0.5> }
            normal { waves 1 frequency 4 phase 0.2 scale <0.5, 1, 1> rotate <0, 0, 30> }
            finish { diffuse 0.7 phong 0.5 phong_size 30 } }
}
