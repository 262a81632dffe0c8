// tests/scenes/nest_probe.pcsg written by hand in POV-Ray's own syntax: a bubble nested in
// faded glass, a water cube overlapping a glass sphere, shadows fading inside the glass.
// `pcsg verify tests/scenes/nest_probe.pcsg --pov tests/povray/nest_probe.pov` must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 10 }

camera {
  perspective
  location <0, -6, 1.5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 1>
  angle 40
}
light_source { <5, -8, 10> color rgb 1 }
background { color rgb <0.1, 0.1, 0.15> }

#declare Clear = finish { ambient 0 diffuse 0 }
#declare Glass = material {
  texture { pigment { color rgbf <1, 1, 1, 0.95> } finish { Clear } }
  interior { ior 1.5 fade_distance 1 fade_power 1001 fade_color rgb <0.2, 0.5, 1> }
}

plane { z, 0 pigment { color rgb 0.7 } }
box { <-2, 2.9, 0>, <2, 3.1, 2> pigment { color rgb <0.9, 0.2, 0.1> } }
sphere { <-0.9, 0, 1>, 1 material { Glass } }
sphere { <-0.9, 0, 1>, 0.5
  material {
    texture { pigment { color rgbt <1, 1, 1, 0.95> } finish { ambient 0 diffuse 0 phong 0.5 } }
    interior { ior 1 }
  }
}
box { <-0.1, -0.8, 0.2>, <1.5, 0.8, 1.8>
  material {
    texture { pigment { color rgbf <0.8, 0.9, 1, 0.9> } finish { Clear } }
    interior { ior 1.33 }
  }
}
sphere { <1.2, -0.3, 1.2>, 0.5 material { Glass } }
