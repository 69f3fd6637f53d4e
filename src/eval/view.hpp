#pragma once
// The viewing-distance measure: how a drawing reads from where it is looked at, whatever
// its marks. The photo and the pen-true render of the drawing lie on the same page grid,
// both are Gaussian-blurred with sigma in millimetres on paper (white paper beyond the
// page) and compared inside the photo's rectangle. The blur is the eye's at a distance
// (0.5 mm close up, 1 mm at arm's length), not the marks' spacing: blurring at the marks'
// own spacing made coarse blobs look as smooth as fine stipples.
//
// Defined as the peers' measure (../shared/peers/measure.py) so the figures compare:
// grey = Rec. 709 weights on the sRGB codes (skimage rgb2gray); the photo resampled
// bilinearly at pixel centres; SSIM with skimage's defaults at 10 px/mm (a 7-pixel box
// window, i.e. 0.7 mm, sample covariance, data range 1, the window's half-width cropped);
// r = Pearson correlation of the blurred greys; tone error = mean |photo - drawing|.
// The window and crop are kept in millimetres, so the figures barely depend on the
// render's resolution (test "sigma in mm ...").
#include <string_view>

#include "geometry/page.hpp"
#include "image/image.hpp"
#include "plan/plan.hpp"

namespace stipplot {

struct ViewOptions {
  double sigma_mm = 1;
  bool colour = false;  // also the mean CIEDE2000 of the blurred colour images
};

struct ViewScore {
  double sigma_mm = 0, px_per_mm = 0;
  double ssim = 0, tone_r = 0, tone_err = 0;
  double mean_photo = 0, mean_drawn = 0;  // blurred grey inside the rectangle, 1 = white
  double delta_e = -1;                    // mean dE00 (ViewOptions::colour), else -1
};

// `drawn_page` is the whole page (tf's) rendered at any resolution, e.g. render_plan.
// O(page pixels x sigma in pixels).
ViewScore view_score(const Image& photo, const PageTransform& tf, const Image& drawn_page, const ViewOptions& opt);

// The same of a plan, rendered pen-true at `px_per_mm`. At sigma >= 0.5 mm a render of
// 4 px/mm suffices (within 0.01 of 8 px/mm, test "sigma in mm ..."): an A4 page is then
// about 1 MP and the comparison O(1 MP x (8 sigma px + 3)), tens of milliseconds; the
// render costs O(the plan's points), seconds for 80k spiral-filled dots (bench_view).
ViewScore view_score_of_plan(const Image& photo, const PageTransform& tf, const Plan& plan, const ViewOptions& opt,
                             double px_per_mm = 4);

// The budget search's call: a drawing before it is planned, its primitives rendered as
// they are (dots as discs, filled circles in their fill colour; render_preview), which the
// blur cannot tell from the plan's fills (test "... of the drawing ..."). O(primitives +
// page pixels x sigma px): a tenth of a second for 80k dots on A4 at 4 px/mm.
ViewScore view_score_of_drawing(const Image& photo, const PageTransform& tf, const Drawing& drawing,
                                const ViewOptions& opt, double px_per_mm = 4);

// The render resolution the CLI measures at: measure.py's 10 px/mm, fewer on pages whose
// render would pass 25 MP.
double view_px_per_mm(double page_w_mm, double page_h_mm);

// --view-sigma: a positive length on paper with its unit (0.5mm, 0.1cm, 2pt). A bare
// number is refused: next to --sigma and --fidelity-sigma, which are input pixels, it
// would be ambiguous. Throws UserError naming `option`.
double parse_view_sigma_mm(std::string_view text, const char* option = "--view-sigma");

}  // namespace stipplot
