// tests/scenes/spotlight_probe.pcsg written by hand in POV-Ray's own syntax: two
// spotlights (radius, falloff, tightness; one fading with distance) and a shadowless light.
// `pcsg verify tests/scenes/spotlight_probe.pcsg --pov tests/povray/spotlight_probe.pov`
// must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -8, 5>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0.5, 0.5>
  angle 45
}
light_source { <-2, -1, 5> color rgb <1, 0.95, 0.8>
  spotlight point_at <-1.2, 0.5, 0> radius 12 falloff 30 tightness 5 }
light_source { <3, -2, 3> color rgb <0.5, 0.7, 1>
  spotlight point_at <1.5, 1, 0> radius 18 falloff 20
  fade_distance 2 fade_power 2 }
light_source { <0, -6, 6> color rgb 0.25 shadowless fade_distance 4 fade_power 1 }
background { color rgb <0.05, 0.05, 0.1> }

#declare Shiny = texture { pigment { color rgb <0.8, 0.3, 0.2> }
                           finish { ambient 0.05 diffuse 0.6 phong 0.8 phong_size 60 } }
plane { z, 0
  texture { pigment { color rgb 0.9 } finish { ambient 0.05 diffuse 0.8 } }
}
sphere { <-1.2, 0.5, 0.6>, 0.6 texture { Shiny } }
box { <1.1, 0.6, 0>, <1.9, 1.4, 0.8> texture { Shiny } }
