// tests/scenes/sky_sphere_probe.pcsg written by hand in POV-Ray's own syntax: a sky_sphere
// with a gradient along z (pcsg's up), seen directly and in a mirror sphere; the background
// colour (red) must not show. `pcsg verify tests/scenes/sky_sphere_probe.pcsg --pov
// tests/povray/sky_sphere_probe.pov` must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -6, 1.5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 1.2>
  angle 60
}
light_source { <-5, -8, 12> color rgb 1 }
background { color rgb <1, 0, 0> }
sky_sphere { pigment { gradient z color_map { [0 rgb <0.9, 0.85, 0.7>] [0.3 rgb <0.35, 0.5, 0.85>]
                                               [1 rgb <0.05, 0.1, 0.4>] } } }

plane { z, 0
  texture { pigment { checker color rgb <0.8, 0.8, 0.8> color rgb <0.3, 0.3, 0.3>
                      translate <0, 0, 0.5> } }
}
sphere { <0, 0, 1>, 1
  texture { pigment { color rgb <0.2, 0.2, 0.2> } finish { reflection 0.8 } }
}
