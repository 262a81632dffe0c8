// tests/scenes/noise_pigment_probe.pcsg written by hand in POV-Ray's own syntax: granite,
// wood with turbulence, marble and agate with their default colour maps, bozo and spotted,
// wrinkles and dents, the turbulence modifiers octaves, omega and lambda.
// `pcsg verify tests/scenes/noise_pigment_probe.pcsg --pov tests/povray/noise_pigment_probe.pov`
// must agree: the tracer's noise against POV-Ray's own, not against the exporter's text.
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
  texture { pigment { granite scale 2
                      color_map { [0 color rgb <0.2, 0.2, 0.25>] [0.5 color rgb <0.7, 0.6, 0.55>]
                                  [1 color rgb <0.95, 0.9, 0.9>] } }
            finish { ambient 0.1 diffuse 0.7 } }
}
sphere { <-1.7, 0, 0.6>, 0.6
  texture { pigment { wood turbulence 0.2 scale <0.15, 0.15, 1> rotate <70, 0, 20>
                      color_map { [0 color rgb <0.75, 0.5, 0.25>] [1 color rgb <0.4, 0.2, 0.08>] } }
            finish { diffuse 0.7 phong 0.3 phong_size 20 } }
}
sphere { <-0.45, 0.9, 0.7>, 0.7
  texture { pigment { marble turbulence 0.8 scale 0.6 } finish { diffuse 0.7 } }
}
sphere { <0, 0, 0>, 0.7
  texture { pigment { agate scale 0.5 } finish { diffuse 0.7 } }
  translate <0.9, 0.9, 0.7>
}
sphere { <1.9, -0.2, 0.5>, 0.5
  texture { pigment { bozo scale 0.3 } finish { diffuse 0.7 } }
}
sphere { <-0.6, -1.5, 0.45>, 0.45
  texture { pigment { spotted turbulence 1.2 octaves 3 omega 0.7 lambda 2.5 scale 0.4 }
            finish { diffuse 0.7 } }
}
torus { 0.45, 0.2 rotate x * 90 translate <0.7, -1.5, 0.25>
  texture { pigment { wrinkles scale 0.4
                      color_map { [0 color rgb <0.1, 0.3, 0.1>] [1 color rgb <0.7, 1, 0.6>] } }
            finish { diffuse 0.7 } }
}
box { <-1, -1, -1>, <1, 1, 1> scale 0.3 translate <1.95, -1.35, 0.3>
  texture { pigment { dents scale 0.2
                      color_map { [0 color rgb <1, 1, 1>] [0.3 color rgb <0.2, 0.2, 0.8>] } }
            finish { diffuse 0.7 } }
}
