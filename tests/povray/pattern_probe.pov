// tests/scenes/pattern_probe.pcsg written by hand in POV-Ray's own syntax: the patterns
// gradient, onion, leopard, radial, brick, hexagon and checker, with colour maps (also the
// [v1, v2 c1 c2] form) and list colours, each texture in world space.
// `pcsg verify tests/scenes/pattern_probe.pcsg --pov tests/povray/pattern_probe.pov` must
// agree: the tracer's patterns against POV-Ray's own, not against the exporter's text.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -6, 5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.3>
  angle 45
}
light_source { <-5, -8, 12> color rgb 1 }
background { color rgb <0.2, 0.25, 0.35> }

plane { z, 0
  texture { pigment { checker color rgb <0.9, 0.9, 0.9> color rgb <0.3, 0.3, 0.35>
                      translate <0, 0, 0.25> scale 0.5 } }
}
sphere { <-1.6, 0.8, 0.6>, 0.6
  texture { pigment { gradient z color_map { [0 rgb <0.9, 0.2, 0.1>] [0.5 rgb <1, 0.9, 0.2>]
                                             [1 rgb <0.1, 0.3, 0.9>] } scale 0.5 } }
}
sphere { <0, 0.8, 0.6>, 0.6
  texture { pigment { onion color_map { [0 rgb 1] [1 rgb <0.2, 0.5, 0.2>] }
                      scale 0.25 translate <0, 0.8, 0.6> } }
}
sphere { <1.6, 0.8, 0.6>, 0.6
  texture { pigment { leopard color_map { [0 rgb <1, 0.8, 0.3>] [0.4 rgb <0.3, 0.2, 0.1>] }
                      scale 0.08 } }
}
sphere { <-1.6, -0.8, 0.6>, 0.6
  texture { pigment { radial frequency 8
                      color_map { [0 rgb <0.9, 0.9, 0.2>] [0.5 rgb <0.2, 0.2, 0.8>]
                                  [1 rgb <0.9, 0.9, 0.2>] }
                      rotate x * 90 translate <-1.6, -0.8, 0> } }
}
sphere { <0, -0.8, 0.6>, 0.6
  texture { pigment { brick color rgb <0.85, 0.85, 0.8> color rgb <0.6, 0.2, 0.1>
                      brick_size <0.4, 0.15, 0.2> mortar 0.03 } }
}
sphere { <1.6, -0.8, 0.6>, 0.6
  texture { pigment { hexagon color rgb <1, 0.3, 0.3> color rgb <0.3, 1, 0.3>
                      color rgb <0.3, 0.3, 1> scale 0.15 rotate x * 90 } }
}
