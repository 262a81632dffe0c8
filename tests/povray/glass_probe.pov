// tests/scenes/glass_probe.pcsg written by hand in POV-Ray's own syntax: filter and
// transmit, refraction through a glass sphere and a glass CSG difference (the interior
// given once, on the difference), fresnel reflection, conserve_energy, fade_distance and
// fade_power, tinted shadows, max_trace_level.
// `pcsg verify tests/scenes/glass_probe.pcsg --pov tests/povray/glass_probe.pov` must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 8 }

camera {
  perspective
  location <0, -8, 3>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.8>
  angle 40
}
light_source { <-4, -10, 12> color rgb 1 }
background { color rgb <0.2, 0.3, 0.5> }

#declare Glass = material {
  texture {
    pigment { color rgbf <0.95, 1, 0.95, 0.9> }
    finish { ambient 0 diffuse 0.05 phong 0.6 phong_size 120
             reflection { 0.02, 1 fresnel on } conserve_energy }
  }
  interior { ior 1.5 fade_distance 2 fade_power 2 }
}
#macro Backdrop(X, C)
  box { <X - 1.2, 2.8, 0>, <X + 1.2, 3.2, 3>
        pigment { color rgb C } finish { ambient 0.1 diffuse 0.6 } }
#end

plane { z, 0 pigment { color rgb <0.8, 0.8, 0.75> } finish { ambient 0.15 diffuse 0.7 } }
Backdrop(-2.5, <0.9, 0.15, 0.1>)
Backdrop(0, <0.1, 0.8, 0.2>)
Backdrop(2.5, <0.15, 0.25, 0.9>)

sphere { <-1.4, 0, 1>, 1 material { Glass } }
difference {
  sphere { <1.4, 0, 1>, 1 }
  box { <0.8, -1.4, 0.7>, <2, -0.2, 1.9> }
  material { Glass }
}
sphere { <-1.6, -2.2, 0.45>, 0.45
  pigment { color rgbf <1, 0.6, 0.1, 0.85> } finish { ambient 0.05 diffuse 0.2 } }
sphere { <1.2, -2.2, 0.45>, 0.45
  pigment { color rgbt <0.3, 0.4, 1, 0.7> } finish { ambient 0.1 diffuse 0.4 } }
