#include "svg/svg_document.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "svg/svg_writer.hpp"
#include "util/threads.hpp"

namespace stipplot {

void open_svg_document(tinyxml2::XMLPrinter& p, const SvgFrame& f) {
  auto num = [&](double v) { return format_number(v, f.decimals); };
  const std::string w = num(f.page.width_mm), h = num(f.page.height_mm);
  p.PushHeader(false, true);
  p.OpenElement("svg");
  p.PushAttribute("xmlns", "http://www.w3.org/2000/svg");
  p.PushAttribute("xmlns:inkscape", "http://www.inkscape.org/namespaces/inkscape");
  if (f.lock_paper) p.PushAttribute("xmlns:sodipodi", "http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd");
  p.PushAttribute("version", "1.1");
  p.PushAttribute("width", (w + "mm").c_str());
  p.PushAttribute("height", (h + "mm").c_str());
  p.PushAttribute("viewBox", ("0 0 " + w + " " + h).c_str());
  p.OpenElement("title");
  p.PushText(f.title.c_str());
  p.CloseElement();
  if (!f.paper_background) return;
  p.OpenElement("g");
  p.PushAttribute("id", "paper");
  p.PushAttribute("inkscape:groupmode", "layer");
  p.PushAttribute("inkscape:label", "% paper (not plotted)");
  if (f.lock_paper) {
    p.PushAttribute("sodipodi:insensitive", "true");
    p.PushAttribute("class", "non-plotting");
  }
  p.OpenElement("rect");
  p.PushAttribute("x", "0");
  p.PushAttribute("y", "0");
  p.PushAttribute("width", w.c_str());
  p.PushAttribute("height", h.c_str());
  p.PushAttribute("fill", f.page.paper.hex().c_str());
  p.PushAttribute("stroke", "none");
  p.CloseElement();
  p.CloseElement();
}

void open_pen_layer(tinyxml2::XMLPrinter& p, int index, const Pen& pen, int decimals) {
  const std::string width = format_number(pen.width_mm, decimals);
  p.OpenElement("g");
  p.PushAttribute("id", ("layer" + std::to_string(index)).c_str());
  p.PushAttribute("inkscape:groupmode", "layer");
  p.PushAttribute("inkscape:label", (std::to_string(index) + " " + pen.name).c_str());
  p.PushAttribute("data-pen-width", width.c_str());
  p.PushAttribute("stroke", pen.color.hex().c_str());
  p.PushAttribute("stroke-width", width.c_str());
  p.PushAttribute("stroke-linecap", "round");
  p.PushAttribute("stroke-linejoin", "round");
  p.PushAttribute("fill", "none");
}

void push_filled_circle(tinyxml2::XMLPrinter& p, Vec2 c, double r, const std::string& fill, int decimals) {
  p.OpenElement("circle");
  p.PushAttribute("cx", format_number(c.x, decimals).c_str());
  p.PushAttribute("cy", format_number(c.y, decimals).c_str());
  p.PushAttribute("r", format_number(r, decimals).c_str());
  p.PushAttribute("fill", fill.c_str());
  p.PushAttribute("stroke", "none");
  p.CloseElement(true);
}

namespace {

// Points [from, to) of a line as one element's attribute text.
void format_piece(const Vec2* pts, size_t from, size_t to, LineElement as, int decimals, std::string& out) {
  out.clear();
  if (as == LineElement::path) out += 'M';
  for (size_t i = from; i < to; ++i) {
    if (as == LineElement::path && i == from + 1) out += " L";
    if (as == LineElement::path || i > from) out += ' ';
    append_number(out, pts[i].x, decimals);
    out += ',';
    append_number(out, pts[i].y, decimals);
  }
}

void push_element(tinyxml2::XMLPrinter& p, LineElement as, const std::string& text) {
  p.OpenElement(as == LineElement::path ? "path" : "polyline");
  p.PushAttribute(as == LineElement::path ? "d" : "points", text.c_str());
  p.CloseElement(true);
}

// Calls f(from, to) for each element a line of n points is split into.
template <class F>
void for_each_piece(size_t n, F&& f) {
  for (size_t from = 0; from < n;) {
    const size_t to = std::min(n, from + kMaxElementPoints);
    f(from, to);
    if (to == n) break;
    from = to - 1;  // the next piece starts where this one ends
  }
}

}  // namespace

void push_line(tinyxml2::XMLPrinter& p, const std::vector<Vec2>& pts, LineElement as, int decimals, std::string& scratch) {
  for_each_piece(pts.size(), [&](size_t from, size_t to) {
    format_piece(pts.data(), from, to, as, decimals, scratch);
    push_element(p, as, scratch);
  });
}

void push_lines(tinyxml2::XMLPrinter& p, const std::vector<const std::vector<Vec2>*>& lines, LineElement as, int decimals) {
  struct Piece {
    const Vec2* pts;
    size_t from, to;
  };
  std::vector<Piece> pieces;
  size_t points = 0;
  for (const auto* line : lines)
    for_each_piece(line->size(), [&](size_t from, size_t to) {
      pieces.push_back({line->data(), from, to});
      points += to - from;
    });
  // Below this a thread costs more than it saves (a drawing of a few thousand points).
  constexpr size_t kWorthAThread = 50'000, kBatch = 256;  // elements: <= 256,000 points a batch
  if (thread_count() < 2 || points < kWorthAThread) {
    std::string scratch;
    for (const Piece& pc : pieces) {
      format_piece(pc.pts, pc.from, pc.to, as, decimals, scratch);
      push_element(p, as, scratch);
    }
    return;
  }
  // Two batches of text: the threads fill one while this one writes the other.
  std::vector<std::string> text[2] = {std::vector<std::string>(kBatch), std::vector<std::string>(kBatch)};
  const size_t batches = (pieces.size() + kBatch - 1) / kBatch;
  FirstError error;  // the first formatting error (a non-finite coordinate)
  auto format = [&](size_t k) {
    const Piece& pc = pieces[k];
    format_piece(pc.pts, pc.from, pc.to, as, decimals, text[(k / kBatch) % 2][k % kBatch]);
  };
  for (size_t k = 0; k < std::min(kBatch, pieces.size()); ++k) format(k);
#pragma omp parallel num_threads(thread_count())
  {
    // Every thread goes through every batch (a thread may not leave a team's loop alone).
    for (size_t b = 0; b < batches; ++b) {
#pragma omp master
      if (!error.failed()) {  // thread 0 writes batch b while the others format batch b + 1
        const size_t first = b * kBatch, last = std::min(pieces.size(), first + kBatch);
        for (size_t k = first; k < last; ++k) push_element(p, as, text[b % 2][k - first]);
      }
      const long first = static_cast<long>((b + 1) * kBatch);
      const long last = static_cast<long>(std::min(pieces.size(), (b + 2) * kBatch));
#pragma omp for schedule(dynamic, 8)
      for (long k = first; k < last; ++k) {
        if (error.failed()) continue;
        error.capture([&] { format(static_cast<size_t>(k)); });
      }  // (the loop's end waits for every thread, thread 0 too: batch b + 1 is complete)
    }
  }
  error.rethrow();
}

}  // namespace stipplot
