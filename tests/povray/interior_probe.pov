// tests/scenes/interior_probe.pcsg written by hand in POV-Ray's own syntax: glass
// objects of one material that overlap or nest, each with its own interior (each
// `material { Glass }` is a separate interior), so a ray inside one that meets the other
// enters a second interior of the same ior and goes on straight.
// `pcsg verify tests/scenes/interior_probe.pcsg --pov tests/povray/interior_probe.pov`
// must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 10 }

camera {
  perspective
  location <0, -7, 1.6>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 1>
  angle 42
}
light_source { <-3, -9, 10> color rgb 1 }
background { color rgb <0.2, 0.3, 0.5> }

#declare Glass = material {
  texture {
    pigment { color rgbf <0.95, 1, 0.95, 0.92> }
    finish { ambient 0 diffuse 0.05 phong 0.6 phong_size 80
             reflection { 0.02, 0.6 fresnel on } }
  }
  interior { ior 1.5 }
}

plane { z, 0 pigment { color rgb <0.8, 0.8, 0.75> } }
box { <-4, 2.85, 0>, <4, 3.25, 3>
  pigment { checker color rgb <0.9, 0.2, 0.1> color rgb <0.95, 0.95, 0.9> scale 0.4 } }
// overlapping
sphere { <-2.3, 0, 1>, 0.8 material { Glass } }
sphere { <-1.5, -0.2, 1.1>, 0.7 material { Glass } }
// nested
sphere { <0.2, 0, 1>, 0.9 material { Glass } }
sphere { <0.2, -0.2, 1>, 0.45 material { Glass } }
// one paint node, two instances
sphere { <1.9, 0, 1>, 0.65 material { Glass } }
sphere { <2.6, -0.3, 1.2>, 0.65 material { Glass } }
