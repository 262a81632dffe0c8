// tests/scenes/clock_probe.pcsg written by hand in POV-Ray's own syntax, reading POV-Ray's
// own `clock` (+K): the camera flies, the light, a colour and the background change, the
// recursion switches rule at clock 0.25, and boxes turn and grow with the clock. Rendered
// with +K<c>, it must agree with `pcsg render tests/scenes/clock_probe.pcsg --clock <c>`:
// the test that the tracer and the exporter do not share one mistake about the time.
//
// pcsg's frame is right-handed with z up; POV-Ray's is left-handed, so the camera looks
// with sky z and a right vector along -x (docs/language.md, the camera). A pcsg cube is
// the box from -1 to 1, its torus lies in the xy-plane, and `move(v) rotz(a) uscale(s)
// X` is X scaled, then turned, then moved.
#version 3.7;
global_settings { assumed_gamma 1.0 max_trace_level 5 }

camera {
  perspective
  location <4 * cos(radians(clock * 360 - 90)), 4 * sin(radians(clock * 360 - 90)), 2 + clock>
  right -x * image_width / image_height
  up y
  direction z
  sky z
  look_at <0, 0, 0.5>
  angle 40
}
light_source { <10, -20 + clock * 10, 30> color rgb 1 }
background { color rgb <0.2, 0.3, 0.3 + 0.4 * clock> }

#declare Warm = texture {
  pigment { color rgb <0.9, 0.5 * clock + 0.2, 0.2> }
  finish { ambient 0.1 diffuse 0.6 phong 0.4 phong_size 30 }
}
#declare Cool = texture {
  pigment { color rgb <0.2, 0.35, 0.8> }
  finish { ambient 0.1 diffuse 0.6 phong 0 }
}

#macro Grow(N)
  #if (clock > 0.25 & N > 0)
    union {
      box { -1, 1 scale 0.35 rotate z * clock * 90 translate <0, 1.2, 0.3> }
      object { Grow(N - 1) scale 0.7 translate <0, 1.2, 1.0> }
    }
  #else
    box { -1, 1 scale 0.4 rotate z * clock * 45 translate <0, 1.2, 0.3> }
  #end
#end

union {
  sphere { 0, 1 scale 0.6 + 0.2 * clock translate <clock * 2 - 1, 0, 0.5> texture { Warm } }
  object { Grow(2) texture { Cool } }
  torus { 1.6, 0.05 + 0.1 * clock rotate x * 90 translate <0, 0, -0.2> texture { Cool } }
}
