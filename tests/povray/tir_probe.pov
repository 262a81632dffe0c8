// tests/scenes/tir_probe.pcsg written by hand in POV-Ray's own syntax: total internal
// reflection in a turned glass cube and a dense sphere, max_trace_level 10.
// `pcsg verify tests/scenes/tir_probe.pcsg --pov tests/povray/tir_probe.pov` must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x; coordinates and rotation angles are the same
// numbers. pcsg applies the transformation nearest the primitive first.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 10 }

camera {
  perspective
  location <0, -7, 1.5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 1>
  angle 38
}
light_source { <5, -8, 10> color rgb 1 }
background { color rgb <0.1, 0.1, 0.15> }

plane { z, 0 pigment { color rgb 0.7 } finish { ambient 0.2 diffuse 0.6 } }
#macro Stripe(X, C)
  box { <X - 0.6, 3.9, 0>, <X + 0.6, 4.1, 3> pigment { color rgb C } }
#end
Stripe(-1.5, <0.9, 0.2, 0.1>)
Stripe(0.3, <0.9, 0.8, 0.1>)
Stripe(2.1, <0.9, 0.2, 0.1>)

box { -1, 1
  scale 0.7 rotate <30, 0, 0> rotate <0, 0, 45> translate <-1.2, 0, 1.2>
  material {
    texture { pigment { color rgbf <0.8, 0.9, 1, 0.95> } finish { ambient 0 diffuse 0 reflection 0.05 } }
    interior { ior 1.5 }
  }
}
sphere { <1.4, 0, 1>, 0.8
  material {
    texture { pigment { color rgbt <1, 1, 1, 0.9> } finish { ambient 0.05 diffuse 0.1 phong 0.8 phong_size 200 } }
    interior { ior 2.4 }
  }
}
