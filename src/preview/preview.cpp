#include "preview/preview.hpp"

#include <cairo.h>
#include <png.h>
#include <stb_image_write.h>

#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <memory>
#include <vector>

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
  bool first = true;
  for (const auto& layer : plan.layers) {
    if (layer.strokes.empty()) continue;
    const double w = layer.pen.width_mm;
    const bool multiply = opt.ink_multiplies && luminance(layer.pen.color) < paper_lum;
    // On the bare paper (one colour) the group's composite is the ink (times the paper
    // where it multiplies) laid over it: drawn straight, without a page-sized group.
    const bool direct = first;
    first = false;
    if (direct) {
      const Color p = plan.page.paper, k = layer.pen.color;
      auto times = [](uint8_t a, uint8_t b) { return static_cast<uint8_t>((a * b + 127) / 255); };
      set_colour(c, multiply ? Color{times(k.r, p.r), times(k.g, p.g), times(k.b, p.b)} : k);
    } else {
      cairo_push_group_with_content(c, CAIRO_CONTENT_COLOR_ALPHA);
      set_colour(c, layer.pen.color);
    }
    cairo_set_operator(c, CAIRO_OPERATOR_OVER);
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
    if (direct) continue;
    cairo_pop_group_to_source(c);
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
// A PNG of `height` rows of RGB, each filled by row(y, buffer). libpng at zlib level 3 and
// no row filter: a preview is mostly paper, where that is both the fastest (5x cairo's
// own writer on an A4 preview) and the smallest of the choices (docs/figures.md).
template <class Row>
void write_rgb_png(int width, int height, const std::string& path, Row&& row) {
  AtomicFile out(path);
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(out.temp_path().c_str(), "wb"), &std::fclose);
  if (!f) throw UserError("cannot write " + path);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw UserError("cannot allocate the PNG writer for " + path);
  }
  std::vector<png_byte> buf(static_cast<size_t>(width) * 3);
  // libpng reports errors by longjmp: nothing with a destructor is made between here and
  // the writes below.
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw UserError("cannot write " + path);
  }
  png_init_io(png, f.get());
  png_set_compression_level(png, 3);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) png_write_row(png, row(y, buf.data()));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(f.get()) != 0 || std::ferror(f.get())) throw UserError("cannot write " + path);
  f.reset();
  out.commit();
}

void write_surface_png(cairo_surface_t* surf, const std::string& path) {
  cairo_surface_flush(surf);
  const int w = cairo_image_surface_get_width(surf), h = cairo_image_surface_get_height(surf);
  const int stride = cairo_image_surface_get_stride(surf);
  const unsigned char* data = cairo_image_surface_get_data(surf);
  write_rgb_png(w, h, path, [&](int y, png_byte* out) {
    const uint32_t* px = reinterpret_cast<const uint32_t*>(data + static_cast<size_t>(y) * stride);
    for (int x = 0; x < w; ++x, out += 3) {  // RGB24: xRGB in a native word
      out[0] = static_cast<png_byte>(px[x] >> 16);
      out[1] = static_cast<png_byte>(px[x] >> 8);
      out[2] = static_cast<png_byte>(px[x]);
    }
    return out - 3 * static_cast<size_t>(w);
  });
}
}  // namespace

void write_preview_png(const Drawing& d, const std::string& path, const PreviewOptions& opt) {
  SurfacePtr surf = render_surface(d, opt);
  write_surface_png(surf.get(), path);
}

void write_png(const Image& im, const std::string& path) {
  if (im.width <= 0 || im.height <= 0) throw UserError("cannot write " + path + ": the image is empty");
  write_rgb_png(im.width, im.height, path, [&](int y, png_byte*) {
    return const_cast<png_byte*>(im.rgb.data() + static_cast<size_t>(y) * im.width * 3);
  });
}

void write_tga(const Image& im, const std::string& path) {
  if (im.width <= 0 || im.height <= 0) throw UserError("cannot write " + path + ": the image is empty");
  AtomicFile out(path);
  stbi_write_tga_with_rle = 0;
  if (!stbi_write_tga(out.temp_path().c_str(), im.width, im.height, 3, im.rgb.data())) throw UserError("cannot write " + path);
  out.commit();
}

}  // namespace stipplot
