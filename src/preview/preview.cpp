#include "preview/preview.hpp"

#include <cairo.h>

#include <cmath>
#include <memory>

#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot {

namespace {

using SurfacePtr = std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)>;
using CairoPtr = std::unique_ptr<cairo_t, void (*)(cairo_t*)>;

double luminance(Color c) { return 0.299 * c.r + 0.587 * c.g + 0.114 * c.b; }

void set_colour(cairo_t* cr, Color c) { cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0); }

// A page-sized surface painted with the paper colour, and a context scaled to mm.
struct Canvas {
  SurfacePtr surf{nullptr, &cairo_surface_destroy};
  CairoPtr cr{nullptr, &cairo_destroy};
};

Canvas page_canvas(const Page& page, double dpi) {
  require_range("--preview-dpi", dpi, 10, 2400);
  const double s = dpi / 25.4;  // px per mm
  const double wpx = std::ceil(page.width_mm * s), hpx = std::ceil(page.height_mm * s);
  if (wpx * hpx > 400e6) throw UserError("preview would be " + std::to_string(static_cast<long>(wpx)) + "x" +
                                         std::to_string(static_cast<long>(hpx)) + " pixels; lower --preview-dpi");
  Canvas cv;
  cv.surf.reset(cairo_image_surface_create(CAIRO_FORMAT_RGB24, static_cast<int>(wpx), static_cast<int>(hpx)));
  if (cairo_surface_status(cv.surf.get()) != CAIRO_STATUS_SUCCESS) throw UserError("cannot allocate the preview image");
  cv.cr.reset(cairo_create(cv.surf.get()));
  cairo_t* c = cv.cr.get();
  set_colour(c, page.paper);
  cairo_paint(c);
  cairo_scale(c, s, s);
  cairo_set_line_cap(c, CAIRO_LINE_CAP_ROUND);
  cairo_set_line_join(c, CAIRO_LINE_JOIN_ROUND);
  return cv;
}

SurfacePtr render_surface(const Drawing& d, const PreviewOptions& opt) {
  Canvas cv = page_canvas(d.page, opt.dpi);
  cairo_t* c = cv.cr.get();
  const double paper_lum = luminance(d.page.paper);
  for (const auto& layer : d.layers) {
    const bool multiply = opt.ink_multiplies && luminance(layer.pen.color) < paper_lum;
    cairo_set_operator(c, multiply ? CAIRO_OPERATOR_MULTIPLY : CAIRO_OPERATOR_OVER);
    set_colour(c, layer.pen.color);
    // Dots: one path per layer is far faster than a fill per dot; overlaps within a
    // layer are the same ink anyway (non-zero winding fills them once).
    cairo_new_path(c);
    for (const auto& dot : layer.dots) {
      cairo_new_sub_path(c);
      cairo_arc(c, dot.c.x, dot.c.y, std::max(dot.diameter, layer.pen.width_mm) / 2, 0, 2 * M_PI);
    }
    cairo_set_fill_rule(c, CAIRO_FILL_RULE_WINDING);
    cairo_fill(c);
    for (const auto& circ : layer.circles) {
      cairo_new_path(c);
      cairo_arc(c, circ.c.x, circ.c.y, circ.r, 0, 2 * M_PI);
      if (circ.filled) {
        set_colour(c, circ.fill);
        cairo_fill(c);
        set_colour(c, layer.pen.color);
      } else {
        cairo_set_line_width(c, layer.pen.width_mm);
        cairo_stroke(c);
      }
    }
    for (const auto& area : layer.areas) {
      cairo_new_path(c);
      for (const auto& ring : area.rings) {
        if (ring.pts.size() < 3) continue;
        cairo_move_to(c, ring.pts[0].x, ring.pts[0].y);
        for (size_t i = 1; i < ring.pts.size(); ++i) cairo_line_to(c, ring.pts[i].x, ring.pts[i].y);
        cairo_close_path(c);
      }
      cairo_set_fill_rule(c, area.rule == FillRule::evenodd ? CAIRO_FILL_RULE_EVEN_ODD : CAIRO_FILL_RULE_WINDING);
      set_colour(c, area.fill);
      cairo_fill(c);
      set_colour(c, layer.pen.color);
    }
    cairo_set_line_width(c, layer.pen.width_mm);
    for (const auto& pl : layer.lines) {
      if (pl.pts.empty()) continue;
      cairo_new_path(c);
      cairo_move_to(c, pl.pts[0].x, pl.pts[0].y);
      if (pl.pts.size() == 1) cairo_line_to(c, pl.pts[0].x, pl.pts[0].y);
      for (size_t i = 1; i < pl.pts.size(); ++i) cairo_line_to(c, pl.pts[i].x, pl.pts[i].y);
      cairo_stroke(c);
    }
  }
  cv.cr.reset();
  cairo_surface_flush(cv.surf.get());
  return std::move(cv.surf);
}

// Each pen's strokes as one group (the union of its ink), then composited: multiplied
// with the page where the ink is darker than the paper, over it where lighter.
SurfacePtr render_plan_surface(const Plan& plan, const PreviewOptions& opt) {
  Canvas cv = page_canvas(plan.page, opt.dpi);
  cairo_t* c = cv.cr.get();
  const double paper_lum = luminance(plan.page.paper);
  for (const auto& layer : plan.layers) {
    if (layer.strokes.empty()) continue;
    const double w = layer.pen.width_mm;
    cairo_push_group_with_content(c, CAIRO_CONTENT_COLOR_ALPHA);
    cairo_set_operator(c, CAIRO_OPERATOR_OVER);
    set_colour(c, layer.pen.color);
    // Touches first, all in one fill; then the strokes in one stroke call: one path a
    // call is far faster than a call a stroke, and the union is the same ink.
    cairo_new_path(c);
    for (const Stroke& st : layer.strokes) {
      if (st.pts.size() != 1) continue;
      cairo_new_sub_path(c);
      cairo_arc(c, st.pts[0].x, st.pts[0].y, w / 2, 0, 2 * M_PI);
    }
    cairo_set_fill_rule(c, CAIRO_FILL_RULE_WINDING);
    cairo_fill(c);
    cairo_set_line_width(c, w);
    for (const Stroke& st : layer.strokes) {
      if (st.pts.size() < 2) continue;
      cairo_move_to(c, st.pts[0].x, st.pts[0].y);
      for (size_t i = 1; i < st.pts.size(); ++i) cairo_line_to(c, st.pts[i].x, st.pts[i].y);
    }
    cairo_stroke(c);
    cairo_pop_group_to_source(c);
    const bool multiply = opt.ink_multiplies && luminance(layer.pen.color) < paper_lum;
    cairo_set_operator(c, multiply ? CAIRO_OPERATOR_MULTIPLY : CAIRO_OPERATOR_OVER);
    cairo_paint(c);
    cairo_set_source_rgb(c, 0, 0, 0);
  }
  cv.cr.reset();
  cairo_surface_flush(cv.surf.get());
  return std::move(cv.surf);
}

Image to_image(cairo_surface_t* surf) {
  Image im;
  im.width = cairo_image_surface_get_width(surf);
  im.height = cairo_image_surface_get_height(surf);
  const int stride = cairo_image_surface_get_stride(surf);
  const unsigned char* data = cairo_image_surface_get_data(surf);
  im.rgb.resize(im.pixels() * 3);
  for (int y = 0; y < im.height; ++y) {
    const uint32_t* row = reinterpret_cast<const uint32_t*>(data + static_cast<size_t>(y) * stride);
    for (int x = 0; x < im.width; ++x) {
      uint32_t px = row[x];
      size_t o = (static_cast<size_t>(y) * im.width + x) * 3;
      im.rgb[o] = static_cast<uint8_t>(px >> 16);
      im.rgb[o + 1] = static_cast<uint8_t>(px >> 8);
      im.rgb[o + 2] = static_cast<uint8_t>(px);
    }
  }
  return im;
}

}  // namespace

Image render_preview(const Drawing& d, const PreviewOptions& opt) { return to_image(render_surface(d, opt).get()); }

Image render_plan(const Plan& plan, const PreviewOptions& opt) { return to_image(render_plan_surface(plan, opt).get()); }

namespace {
void write_surface_png(cairo_surface_t* surf, const std::string& path) {
  AtomicFile out(path);
  if (cairo_surface_write_to_png(surf, out.temp_path().c_str()) != CAIRO_STATUS_SUCCESS)
    throw UserError("cannot write " + path);
  out.commit();
}
}  // namespace

void write_preview_png(const Drawing& d, const std::string& path, const PreviewOptions& opt) {
  SurfacePtr surf = render_surface(d, opt);
  write_surface_png(surf.get(), path);
}

void write_png(const Image& im, const std::string& path) {
  SurfacePtr surf(cairo_image_surface_create(CAIRO_FORMAT_RGB24, im.width, im.height), &cairo_surface_destroy);
  if (cairo_surface_status(surf.get()) != CAIRO_STATUS_SUCCESS) throw UserError("cannot allocate image for " + path);
  cairo_surface_flush(surf.get());
  unsigned char* data = cairo_image_surface_get_data(surf.get());
  const int stride = cairo_image_surface_get_stride(surf.get());
  for (int y = 0; y < im.height; ++y) {
    uint32_t* row = reinterpret_cast<uint32_t*>(data + static_cast<size_t>(y) * stride);
    for (int x = 0; x < im.width; ++x) {
      size_t o = (static_cast<size_t>(y) * im.width + x) * 3;
      row[x] = 0xff000000u | (uint32_t{im.rgb[o]} << 16) | (uint32_t{im.rgb[o + 1]} << 8) | im.rgb[o + 2];
    }
  }
  cairo_surface_mark_dirty(surf.get());
  write_surface_png(surf.get(), path);
}

}  // namespace stipplot
