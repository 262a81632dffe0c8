// tests/scenes/fog_probe.pcsg written by hand in POV-Ray's own syntax: constant fog with a
// filtered, transmitting colour, seen directly and in a mirror.
// `pcsg verify tests/scenes/fog_probe.pcsg --pov tests/povray/fog_probe.pov` must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -6, 1.5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 4, 0.8>
  angle 50
}
light_source { <-5, -8, 10> color rgb 1 }
background { color rgb <0.9, 0.5, 0.2> }
fog { distance 7 color rgbft <0.5, 0.6, 0.7, 0.3, 0.15> }

#declare Ball = texture { pigment { color rgb <0.9, 0.2, 0.2> }
                          finish { ambient 0.1 diffuse 0.7 phong 0.5 } }
plane { z, 0
  texture { pigment { color rgb <0.3, 0.6, 0.3> } finish { ambient 0.1 diffuse 0.7 } }
}
sphere { <-1.5, 0, 0.5>, 0.5 texture { Ball } }
sphere { <-0.5, 4, 0.5>, 0.5 texture { Ball } }
sphere { <0.5, 9, 0.5>, 0.5 texture { Ball } }
sphere { <1.5, 16, 0.5>, 0.5 texture { Ball } }
sphere { <1.4, 1, 0.7>, 0.7
  texture { pigment { color rgb 0.2 } finish { ambient 0.05 diffuse 0.2 reflection 0.8 } }
}
