// tests/scenes/inside_probe.pcsg written by hand in POV-Ray's own syntax: the camera inside
// a fading glass sphere. POV-Ray starts camera rays inside the objects that contain the
// camera. `pcsg verify tests/scenes/inside_probe.pcsg --pov tests/povray/inside_probe.pov`
// must agree.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x. pcsg's plane is the half-space z <= 0.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <0, -1, 1>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 3, 1>
  angle 50
}
light_source { <5, -8, 10> color rgb 1 }
background { color rgb <0.1, 0.1, 0.15> }

plane { z, 0 pigment { color rgb 0.7 } }
box { <-1, 3.9, 0>, <0, 4.1, 2> pigment { color rgb <0.9, 0.2, 0.1> } }
box { <0, 3.9, 0>, <1, 4.1, 2> pigment { color rgb <0.9, 0.8, 0.1> } }
sphere { <0, -1, 1>, 2
  material {
    texture { pigment { color rgbf <1, 1, 1, 0.95> } finish { ambient 0 diffuse 0 } }
    interior { ior 1.5 fade_distance 1 fade_power 2 }
  }
}
