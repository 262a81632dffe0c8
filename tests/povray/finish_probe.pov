// tests/scenes/finish_probe.pcsg written by hand in POV-Ray's own syntax: the floor's
// reflection {min, max}, brilliance, specular and roughness, metallic highlights and
// metallic reflection, fresnel reflection with an interior's ior, conserve_energy.
// `pcsg verify tests/scenes/finish_probe.pcsg --pov tests/povray/finish_probe.pov` must
// agree: the tracer's formulas against POV-Ray's own, not against the exporter's text.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0, its torus
// lies in the xy-plane.
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
  texture { pigment { color rgb <0.45, 0.45, 0.5> }
            finish { ambient 0.1 diffuse 0.6 reflection { 0, 0.6 } } }
}
sphere { <-1.6, 0, 0.7>, 0.7
  texture { pigment { color rgb <0.8, 0.25, 0.2> }
            finish { diffuse 0.7 brilliance 2.5 specular 0.7 roughness 0.02 } }
}
sphere { <0, 0.6, 0.8>, 0.8
  texture { pigment { rgb <0.9, 0.65, 0.2> }
            finish { ambient 0.05 diffuse 0.4 phong 0.9 phong_size 80 metallic
                     reflection { 0.2, 0.7 metallic } } }
}
sphere { <1.7, 0, 0.7>, 0.7
  texture { pigment { color rgbf <0.15, 0.3, 0.6, 0> }
            finish { diffuse 0.5 specular 0.9 roughness 0.005
                     reflection { 0.05, 1 fresnel on } conserve_energy } }
  interior { ior 1.5 }
}
torus { 0.6, 0.25 rotate x * 90 translate <0, -1.6, 0.3>
  texture { pigment { color rgb <0.7, 0.7, 0.75> }
            finish { ambient 0.05 diffuse 0.3 metallic 0.5 specular 0.8 roughness 0.01
                     reflection 0.5 } }
}
