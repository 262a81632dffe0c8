// tests/scenes/area_light_probe.pcsg written by hand in POV-Ray's own syntax: a 6x6 area
// light with adaptive 1, and a 3x3 circular, oriented one sampled in full.
// `pcsg verify tests/scenes/area_light_probe.pcsg --pov tests/povray/area_light_probe.pov`
// must agree: the tracer's area-light sampling against POV-Ray's own.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -7, 4>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.6>
  angle 40
}
light_source { <-4, -1, 3.5> color rgb <0.9, 0.9, 0.85>
  area_light <2, 0, 0>, <0, 2, 0>, 6, 6 adaptive 1 }
light_source { <4, -3, 3> color rgb <0.6, 0.6, 0.7>
  area_light <3, 0, 0>, <0, 0, 3>, 3, 3 circular orient }
background { color rgb <0.2, 0.25, 0.35> }

plane { z, 0
  texture { pigment { color rgb 0.8 } finish { ambient 0.1 diffuse 0.7 } }
}
sphere { <-0.9, 0, 0.8>, 0.8
  texture { pigment { color rgb <0.8, 0.2, 0.15> }
            finish { ambient 0.1 diffuse 0.6 phong 0.6 phong_size 40 } }
}
box { <0.6, 0.1, 0>, <1.6, 1.1, 1>
  texture { pigment { color rgb <0.2, 0.35, 0.8> } finish { ambient 0.1 diffuse 0.6 } }
}
