// The perspective pin-hole camera of docs/language.md section 7, reproducing POV-Ray 3.7.0's
// camera exactly, so that `pcsg verify` can compare the two images pixel by pixel.
//
// The POV-Ray camera block that matches this camera (the exporter writes it)
// -----------------------------------------------------------------------------------
//
//     camera {
//       perspective
//       location <Lx, Ly, Lz>          // Camera::location
//       right -x*R                     // R = W/H, the image's aspect ratio, as a number
//       up y                           //   (%.17g), e.g. `right -x*1.3333333333333333`
//       direction z
//       sky <Sx, Sy, Sz>               // Camera::sky
//       look_at <Ax, Ay, Az>           // Camera::lookAt
//       angle a                        // Camera::angle, the horizontal field of view
//     }
//
// Keep `up y` and `direction z` exactly (their lengths and the sign of `right` decide the
// aspect ratio and the handedness, see below), and put `look_at` and `angle` anywhere in
// the block: POV-Ray 3.7 applies them after all other items, whatever their order.
// Together with `global_settings { assumed_gamma 1.0 }` and POV-Ray's defaults this is
// the camera the native tracer renders. Checked with povray 3.7.0.10 on hand-written
// scenes (tracer/camera_test.cpp): small emissive spheres at known positions appear at
// the pixels this camera predicts, +x on the right, and the native images agree with
// POV-Ray's pixel for pixel (every pixel with 3.7.0.10; the tests allow 3 grazed edge
// pixels), for these cameras (tests PovrayCamera.*):
//   PlusXIsOnTheRightLookingAlongY   along +y, sky +z, 64x48
//   LookingDownZWithSkyYPortrait     down -z, sky +y, 48x64
//   ObliqueWideImage                 oblique, sky +z, 80x40
//   SlantedSky                       sky <0.3,1,0.2>, not perpendicular to the view
//   WideAngleOffAxisCorners          angle 100, spheres near the corners, 63x47
//   LookAtAndAngleFirstInTheBlock    look_at and angle written first in the block
// The PinholeCamera.* tests there check the geometry on its own. The fallback for a sky
// along the view is not checked against POV-Ray: the compiler rejects such a camera.
//
// What POV-Ray 3.7.0 does with that block (source/parser/parse.cpp, Parse_Camera; and
// source/backend/render/tracepixel.cpp, CreateCameraRay), and so what we do:
//
//  1. `angle a`: the direction is normalised and given the length
//         D = |right| / (2 tan(a/2)) = R / (2 tan(a/2)),
//     so `a` is the horizontal field of view.
//  2. `look_at A`: with the handedness h = (up x direction) . right computed from the
//     vectors as given (here (y x z) . (-x R) = -R < 0), POV-Ray sets
//         d = normalize(A - L)
//         s = normalize(sky x d)        (if sky x d is zero: s = normalize(right as given))
//         up = d x s                    (length |up| = 1)
//         direction = D d
//         right = (h > 0 ? +R : -R) s  = -R s here, i.e. R normalize(d x sky)
//     With sky <0,0,1> and d = +y, s = -x, so right = +x R: +x is on the right of the
//     image and the scene is right-handed, as docs/language.md requires.
//  3. A pixel (px, py), px = 0..W-1 from the left, py = 0..H-1 from the top, is sampled
//     at its centre; sub-pixel samples use the same formula with fractional offsets:
//         x0 = (px + 0.5) / W - 0.5,   y0 = 0.5 - (py + 0.5) / H
//         ray direction = normalize(direction + x0 right + y0 up),  origin = L.
//     (POV-Ray 3.7.0 adds 0.5 to x and subtracts 0.5 from y and then computes
//     y0 = ((H - 1) - y) / H - 0.5, which is the same.)
//
// The ray parameter t of a camera ray is the distance from the camera.
#pragma once

#include "geometry.h"
#include "graph.h"

namespace pcsg::tracer {

struct Ray {
    Vec3 origin;
    Vec3 dir;  // unit length in world space; not normalised in child frames
};

class PinholeCamera {
  public:
    PinholeCamera(const Camera& cam, int width, int height);

    // The primary ray through image position (x, y), in pixels from the top-left corner
    // of the image: the centre of pixel (px, py) is (px + 0.5, py + 0.5).
    Ray ray(double x, double y) const;

    const Vec3& direction() const { return direction_; }
    const Vec3& right() const { return right_; }
    const Vec3& up() const { return up_; }

  private:
    Vec3 location_;
    Vec3 direction_, right_, up_;  // POV-Ray's vectors after look_at and angle
    double width_, height_;
};

}  // namespace pcsg::tracer
