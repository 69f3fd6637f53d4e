// stipplot tree: dendritic drawings by anisotropic minimum spanning trees, and
// terrain maps (seed 002).
#include <memory>

#include "cli/commands.hpp"
#include "cli/method_command.hpp"
#include "methods/tree/tree.hpp"
#include "methods/working_grid.hpp"
#include "util/error.hpp"
#include "util/units.hpp"

namespace stipplot::cli {

namespace {
struct TreeArgs {
  std::string distance = "auto";
  tree::TreeParams p;
  tree::TerrainParams t;
  bool separate = false;
  std::string retrace = "auto";
  std::string law = "tone";
  std::string weight = "auto";
  std::string a = "auto";
  double weight_pens = 1;  // --weight, read once the options are checked
};

// Under the tone law each point lays ink along about 1.3 spacings of line (a tree of
// Poisson-disc points), so a line `weight` pens wide lays the darkness t with points
// weight / (1.3 t) cells apart: a = 0.62 x weight gives the photo's whole tone at the
// finest density (coffee.png: blurred mean grey 0.42 drawn for the photo's 0.39, weight
// 2). The paper's a is 2 (linear law).
constexpr double kToneSpacingPerWeight = 0.62;

// "auto" or a number >= lo for `option` (no unit: pen widths or grid cells).
double auto_or_number(const std::string& text, double automatic, const char* option, double lo) {
  if (text == "auto") return automatic;
  double v = 0;
  std::string unit;
  if (!split_number_unit(text, v, unit) || !unit.empty())
    throw UserError(std::string(option) + ": must be a finite decimal number or auto, not '" + text + "'");
  if (v < lo) throw UserError(std::string(option) + " must be >= " + std::to_string(static_cast<int>(lo)) + " (or auto)");
  return v;
}

// --weight auto: two pens wide under the tone law (the hour's drawing), the pen's own
// line under the paper's linear law or where --separate or --retrace asks for single lines.
double weight_of(const TreeArgs& a) {
  const bool heavy = a.law == "tone" && !a.separate && a.retrace == "auto";
  return auto_or_number(a.weight, heavy ? 2 : 1, "--weight", 1);
}

// The pen-down line that takes as long as one pen drop and lift on the profile: an edge
// shorter than this is cheaper drawn back along than left by lifting. O(log) line times.
double lift_length_mm(const budget::MarkCosts& costs) {
  const double lift = costs.pen_cycle_s();
  if (!(lift > 0)) return 0;
  double lo = 0, hi = 1000;
  for (int i = 0; i < 40; ++i) {
    const double mid = (lo + hi) / 2;
    (costs.line_s(mid) < lift ? lo : hi) = mid;
  }
  return lo;
}

tree::TreeStrokes strokes_for(const TreeArgs& a, const budget::MarkCosts& costs) {
  tree::TreeStrokes s;
  s.link = !a.separate;
  s.weight = a.weight_pens;
  s.retrace_mm = a.retrace == "auto" ? lift_length_mm(costs) : parse_paper_mm(a.retrace, "--retrace");
  return s;
}

nlohmann::json tree_summary(const tree::TreeResult& r, const tree::TreeParams& p, const tree::TreeStrokes& strokes) {
  nlohmann::json s;
  s["distance"] = p.variant.name;
  s["law"] = p.tone_law ? "tone" : "linear";
  s["a_cells"] = p.a;  // at this density (the budget's spacing scale included)
  s["weight_pens"] = strokes.link ? strokes.weight : 1;
  s["strokes"] = !strokes.link ? "separate" : strokes.weight > 1 ? "loops" : "trails";
  s["points"] = r.points.size();
  s["stipples"] = r.stipple_count;
  s["edge_pixels"] = r.points.size() - r.stipple_count;
  s["mst"] = p.reference_prim ? "prim-reference" : "boruvka-kdtree";
  nlohmann::json trees = nlohmann::json::array();
  for (const auto& l : r.layers)
    trees.push_back({{"distance", tree::to_string(l.kind)},
                     {"edges", l.edges.size()},
                     {"total_cost", tree::total_cost(l.edges)},
                     {"bridges_left_out", l.bridges},
                     {"mean_abs_cos_gradient", l.mean_abs_cos},
                     {"edges_measured", l.measured}});
  s["trees"] = trees;
  s["seconds_points"] = r.seconds_points;
  s["seconds_edges"] = r.seconds_edges;
  s["seconds_mst"] = r.seconds_mst;
  return s;
}
}  // namespace

void register_tree(CLI::App& app) {
  auto args = std::make_shared<TreeArgs>();
  auto m = MethodCommand::add(
      app, "tree", "Dendritic drawing: stipples joined by an anisotropic minimum spanning tree",
      "Distances: ed (Euclidean: lines in every direction), bd (bilateral: lines along iso-intensity\n"
      "contours), sibd (sign-inverted bilateral: lines down the intensity gradient), bd+sibd (both, two\n"
      "layers: tile-like). Cross variants ced, cbd, csibd, cbd+csibd add the major edges (mean shift +\n"
      "Canny) to the points and measure intensity as the distance from those edges.\n"
      "--terrain writes a terrain map: the tree as valleys in the image (or edge distance) as height,\n"
      "bump-map shaded, high ground red, low ground green, edges blue.\n"
      "Under --law tone (the default) each tree is one closed loop round it, a line two pens wide with rounded\n"
      "corners (--weight 2): the photo's tone in half the corners a plotter slows for, no lift inside a tree.\n"
      "With --weight 1 (the default under --law linear) a tree is drawn as few pen-down trails of single lines:\n"
      "an edge is drawn back along where that is quicker than a pen lift (--retrace), and every edge is its own\n"
      "stroke with --separate (the paper's drawing, a lift each).\n"
      "Example: stipplot tree photo.jpg -o tree.svg --distance sibd --preview tree.png --terrain land.png");
  CLI::App* cmd = m->cli();
  cmd->add_option("-d,--distance", args->distance,
                  "auto|ed|bd|sibd|bd+sibd|ced|cbd|csibd|cbd+csibd; auto = ed under --law tone (the hour's drawing:\n"
                  "its ink follows the tone), sibd under --law linear (the paper's look)")
      ->capture_default_str();
  m->add_png_output("--terrain", "Also write a terrain map PNG (image size)", "terrain", "terrain");
  const char* g = "Tree";
  cmd->add_option("-a", args->a,
                  "Stipple radius offset a, in grid cells (a cell is one pen width on paper): r = a + b*d/255 (--law linear), "
                  "a/t (--law tone); auto = 2 (the paper's) under linear, 0.62 x --weight under tone (the photo's whole tone)")
      ->capture_default_str()->group(g);
  cmd->add_option("-b", args->p.b, "Stipple radius slope b, in grid cells")->capture_default_str()->group(g);
  cmd->add_option("--law", args->law,
                  "tone: points a/t apart for darkness t (up to a+b; lighter ground empty, no edge across it), so the\n"
                  "lines' ink follows the photo's tone; linear: the paper's r = a + b*d/255 over the whole image")
      ->capture_default_str()->group(g);
  cmd->add_option("--alpha-bd", args->p.alpha_bd, "BD/CBD: weight of the intensity difference")->capture_default_str()->group(g);
  cmd->add_option("--alpha-sibd", args->p.alpha_sibd, "SIBD/CSIBD: weight of the penalty")->capture_default_str()->group(g);
  cmd->add_option("--h", args->p.h, "SIBD/CSIBD: threshold h on the squared intensity difference")->capture_default_str()->group(g);
  cmd->add_option("--sigma", args->p.sigma, "Gaussian blur (grid cells) of the image for BD/SIBD intensities; 0 = none")->capture_default_str()->group(g);
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")->capture_default_str()->group(g);
  cmd->add_flag("--reference-prim", args->p.reference_prim, "Use the paper's O(n^2) Prim (slow; for comparison)")->group(g);
  cmd->add_flag("--separate", args->separate, "Draw every edge as a stroke of its own (a pen lift each) instead of linked trails")->group(g);
  cmd->add_option("--retrace", args->retrace,
                  "Draw an edge back along, pen down, rather than lift where it is shorter than this: mm, cm, in, pt or px; "
                  "auto = the line a pen lift's time draws on --profile; 0 = never")
      ->capture_default_str()->group(g);
  cmd->add_option("--weight", args->weight,
                  "Line weight in pen widths (>= 1): 1 = the pen's own line (linked trails); over 1, each tree is one closed loop\n"
                  "round it, (weight - 1) / 2 pen widths to either side of its edges, its corners rounded; auto = 2 under --law\n"
                  "tone (a line two pens wide: the tone in half the corners, no lift inside a tree), 1 under --law linear")
      ->capture_default_str()->group(g);
  const char* e = "Major edges (cross variants)";
  cmd->add_option("--ms-spatial", args->p.edges.spatial_radius, "Mean-shift spatial radius (px)")->capture_default_str()->group(e);
  cmd->add_option("--ms-color", args->p.edges.color_radius, "Mean-shift colour radius")->capture_default_str()->group(e);
  cmd->add_option("--ms-scale", args->p.edges.scale, "Run the mean shift on the image scaled by this (speed)")->capture_default_str()->group(e);
  cmd->add_option("--canny-low", args->p.edges.canny_low, "Canny low threshold")->capture_default_str()->group(e);
  cmd->add_option("--canny-high", args->p.edges.canny_high, "Canny high threshold")->capture_default_str()->group(e);
  cmd->add_option("--min-edge-length", args->p.edges.min_length, "Drop edge chains with fewer pixels")->capture_default_str()->group(e);
  cmd->add_option("--dt-gain", args->p.dt_gain, "Edge distance to intensity (grey levels per px); 0 = scale to 0..255")->capture_default_str()->group(e);
  const char* t = "Terrain";
  cmd->add_option("--valley-depth", args->t.valley_depth, "Height added per px of distance from the tree")->capture_default_str()->group(t);
  cmd->add_option("--relief", args->t.relief, "Bump-mapping strength")->capture_default_str()->group(t);
  cmd->add_option("--light-azimuth", args->t.azimuth, "Light direction, degrees clockwise from up")->capture_default_str()->group(t);
  cmd->add_option("--light-elevation", args->t.elevation, "Light elevation, degrees")->capture_default_str()->group(t);
  m->define(
      [args] {
        if (args->law != "tone" && args->law != "linear") throw UserError("--law: unknown law '" + args->law + "' (use tone or linear)");
        args->p.tone_law = args->law == "tone";
        // Under the tone law SIBD's trees shun the edges they would cross: a white halo along
        // every edge and a fur of short edges on it, the tone lost (coffee.png at 1 h, seen
        // at 1 mm: tone r 0.65 against ED's 0.90, SSIM 0.59 against 0.65).
        args->p.variant = tree::parse_variant(args->distance == "auto" ? (args->p.tone_law ? "ed" : "sibd") : args->distance);
        const double weight = args->weight_pens = weight_of(*args);
        if (weight > 1 && args->separate) throw UserError("--separate draws every edge once: use it with --weight 1");
        if (weight > 1 && args->retrace != "auto") throw UserError("--retrace belongs to --weight 1 (a heavier line is one loop a tree)");
        args->p.a = auto_or_number(args->a, args->p.tone_law ? kToneSpacingPerWeight * weight : 2, "-a", 0);
        args->p.validate();
        args->t.validate();
        if (args->retrace != "auto" && !(parse_paper_mm(args->retrace, "--retrace") >= 0))
          throw UserError("--retrace must be >= 0 (or auto)");
        if (args->separate && args->retrace != "auto") throw UserError("--retrace belongs to linked trails, not --separate");
      },
      [args](const MethodInput& in) { return spaced_density(in, [args, &in](double spacing) {
        tree::TreeParams p = args->p;
        p.a *= spacing, p.b *= spacing;  // the stipple radii: points about 1 / spacing^2 as many
        // On a grid of one pen width a cell: the same page and pen give the same tree
        // whatever the file's resolution (-a, -b, --sigma are in its cells).
        const WorkingGrid grid = make_working_grid(in.image, in.placement.transform(in.image.width, in.image.height),
                                                   in.placement.pen_width_mm);
        auto r = std::make_shared<tree::TreeResult>(tree::tree_pixels(grid.image, p));
        MethodResult out;
        const tree::TreeStrokes strokes = strokes_for(*args, in.costs);
        out.drawing = tree::place_tree(*r, in.placement, strokes);
        out.summary = tree_summary(*r, p, strokes);
        out.images["--terrain"] = [r, args] { return tree::terrain(*r, args->t); };
        out.counts = std::to_string(r->points.size()) + " points, " + std::to_string(out.drawing.primitive_count()) +
                     " segments in " + layers_phrase(out.drawing.layers.size()) + " (" + p.variant.name + ", " +
                     pixel_size(in.image) + " on a " + pixel_size(grid.image) + " grid)";
        return out;
      }); });
}

}  // namespace stipplot::cli
