// tests/scenes/pattern_space_probe.pcsg written by hand in POV-Ray's own syntax: a texture
// given before an object's transformations moves with it, one given after them does not;
// a pattern's scale, rotate, translate, frequency and phase; a normal on a transformed object.
// `pcsg verify tests/scenes/pattern_space_probe.pcsg --pov tests/povray/pattern_space_probe.pov`
// must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's rotz(a) rotx(b) X rotates X about x
// first, then about z: POV-Ray's rotate x * b rotate z * a.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -6, 4.5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.4>
  angle 45
}
light_source { <-5, -8, 12> color rgb 1 }
background { color rgb <0.2, 0.25, 0.35> }

#declare Rings = texture { pigment { onion color_map { [0 rgb <0.95, 0.9, 0.8>]
                                                       [0.5 rgb <0.3, 0.2, 0.6>]
                                                       [1 rgb <0.95, 0.9, 0.8>] } scale 0.4 } }

plane { z, 0
  texture { pigment { gradient <1, 1, 0> frequency 2 phase 0.3
                      color_map { [0 rgb <0.8, 0.8, 0.85>] [1 rgb <0.3, 0.35, 0.5>] }
                      scale <2, 1, 1> rotate <0, 0, 25> translate <0.3, 0, 0> } }
}
sphere { 0, 1 texture { Rings } scale 0.7 translate <-1.6, 0.8, 0.7> }
sphere { <1.6, 0.8, 0.7>, 0.7 texture { Rings } }
sphere { 0, 1
  texture { pigment { gradient x color_map { [0 rgb <0.9, 0.5, 0.1>] [0.5 rgb <0.9, 0.5, 0.1>]
                                             [0.5 rgb <0.1, 0.4, 0.3>] [1 rgb <0.1, 0.4, 0.3>] }
                      scale 0.3 } }
  scale <0.7, 0.7, 0.9> rotate x * 20 rotate z * 35 translate <0, -0.9, 0.7>
}
sphere { 0, 1
  texture { pigment { color rgb <0.8, 0.75, 0.3> }
            normal { ripples 1.5 frequency 3 translate <0, 0, 0.4> }
            finish { phong 0.6 phong_size 40 } }
  scale <0.3, 0.8, 0.55> rotate x * 50 rotate z * 60 translate <1.9, -0.8, 0.6>
}
