// tests/scenes/ground_fog_probe.pcsg written by hand in POV-Ray's own syntax: ground fog
// (fog_type 2) whose altitude is measured along z, pcsg's up.
// `pcsg verify tests/scenes/ground_fog_probe.pcsg --pov tests/povray/ground_fog_probe.pov`
// must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -8, 1.2>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 1.2>
  angle 55
}
light_source { <-6, -10, 12> color rgb 1 }
background { color rgb <0.3, 0.45, 0.8> }
fog { fog_type 2 distance 2.5 color rgb <0.85, 0.85, 0.9> fog_offset 0.4 fog_alt 0.5 up z }

#declare Stone = texture { pigment { color rgb <0.7, 0.7, 0.65> }
                           finish { ambient 0.1 diffuse 0.7 } }
plane { z, 0
  texture { pigment { color rgb <0.4, 0.35, 0.3> } finish { ambient 0.1 diffuse 0.7 } }
}
cylinder { <-2, 0, 0>, <-2, 0, 2.5>, 0.3 texture { Stone } }
cylinder { <0, 3, 0>, <0, 3, 2.5>, 0.3 texture { Stone } }
cylinder { <2, 7, 0>, <2, 7, 2.5>, 0.3 texture { Stone } }
