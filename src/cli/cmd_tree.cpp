// stipplot tree: dendritic drawings by anisotropic minimum spanning trees, and
// terrain maps (seed 002).
#include <filesystem>
#include <memory>
#include <sstream>

#include "cli/commands.hpp"
#include "cli/common.hpp"
#include "methods/tree/tree.hpp"
#include "preview/preview.hpp"
#include "util/atomic_file.hpp"
#include "util/error.hpp"

namespace stipplot::cli {

namespace {
struct TreeArgs {
  OutputArgs out;
  PlacementArgs place;
  std::string distance = "sibd";
  std::string terrain;
  tree::TreeParams p;
  tree::TerrainParams t;
};
}  // namespace

void register_tree(CLI::App& app) {
  auto args = std::make_shared<TreeArgs>();
  CLI::App* cmd = app.add_subcommand("tree", "Dendritic drawing: stipples joined by an anisotropic minimum spanning tree");
  cmd->footer(
      "Distances: ed (Euclidean: lines in every direction), bd (bilateral: lines along iso-intensity\n"
      "contours), sibd (sign-inverted bilateral: lines down the intensity gradient), bd+sibd (both, two\n"
      "layers: tile-like). Cross variants ced, cbd, csibd, cbd+csibd add the major edges (mean shift +\n"
      "Canny) to the points and measure intensity as the distance from those edges.\n"
      "--terrain writes a terrain map: the tree as valleys in the image (or edge distance) as height,\n"
      "bump-map shaded, high ground red, low ground green, edges blue.\n"
      "Example: stipplot tree photo.jpg -o tree.svg --distance sibd --preview tree.png --terrain land.png");
  add_output_options(cmd, args->out);
  add_placement_options(cmd, args->place);
  cmd->add_option("-d,--distance", args->distance, "ed|bd|sibd|bd+sibd|ced|cbd|csibd|cbd+csibd")->capture_default_str();
  cmd->add_option("--terrain", args->terrain, "Also write a terrain map PNG (image size)")->group("Output");
  const char* g = "Tree";
  cmd->add_option("-a", args->p.a, "Stipple radius offset a (px): r = a + b*d/255")->capture_default_str()->group(g);
  cmd->add_option("-b", args->p.b, "Stipple radius slope b (px)")->capture_default_str()->group(g);
  cmd->add_option("--alpha-bd", args->p.alpha_bd, "BD/CBD: weight of the intensity difference")->capture_default_str()->group(g);
  cmd->add_option("--alpha-sibd", args->p.alpha_sibd, "SIBD/CSIBD: weight of the penalty")->capture_default_str()->group(g);
  cmd->add_option("--h", args->p.h, "SIBD/CSIBD: threshold h on the squared intensity difference")->capture_default_str()->group(g);
  cmd->add_option("--sigma", args->p.sigma, "Gaussian blur (px) of the input for BD/SIBD intensities; 0 = none")->capture_default_str()->group(g);
  cmd->add_option("--seed", args->p.seed, "Random seed; the same seed gives the same drawing")->capture_default_str()->group(g);
  cmd->add_flag("--reference-prim", args->p.reference_prim, "Use the paper's O(n^2) Prim (slow; for comparison)")->group(g);
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
  cmd->callback([args] {
    auto t0 = std::chrono::steady_clock::now();
    TreeArgs& a = *args;
    a.p.variant = tree::parse_variant(a.distance);
    a.p.validate();
    a.t.validate();
    Placement placement = a.place.resolve();
    a.out.validate();
    if (!a.terrain.empty()) {
      std::string ext = std::filesystem::path(a.terrain).extension().string();
      for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      if (ext != ".png") throw UserError("--terrain " + a.terrain + ": the terrain map is a PNG file");
      require_writable_dir(a.terrain);
    }
    Image img = load_input(a.out);
    tree::TreeResult r = tree::tree_pixels(img, a.p);
    Drawing d = tree::place_tree(r, placement);
    nlohmann::json s;
    s["command"] = "tree";
    s["distance"] = a.p.variant.name;
    s["input"] = a.out.input;
    s["image_px"] = {img.width, img.height};
    s["points"] = r.points.size();
    s["stipples"] = r.stipple_count;
    s["edge_pixels"] = r.points.size() - r.stipple_count;
    s["mst"] = a.p.reference_prim ? "prim-reference" : "boruvka-kdtree";
    nlohmann::json trees = nlohmann::json::array();
    for (const auto& l : r.layers)
      trees.push_back({{"distance", tree::to_string(l.kind)},
                       {"edges", l.edges.size()},
                       {"total_cost", tree::total_cost(l.edges)},
                       {"mean_abs_cos_gradient", l.mean_abs_cos},
                       {"edges_measured", l.measured}});
    s["trees"] = trees;
    s["seconds_points"] = r.seconds_points;
    s["seconds_edges"] = r.seconds_edges;
    s["seconds_mst"] = r.seconds_mst;
    write_outputs(d, a.out, s);
    if (!a.terrain.empty()) {
      write_png(tree::terrain(r, a.t), a.terrain);
      s["terrain"] = a.terrain;
    }
    s["seconds"] = seconds_since(t0);
    std::ostringstream hs;
    hs << "wrote " << a.out.output << ": " << r.points.size() << " points, " << d.primitive_count() << " segments in "
       << d.layers.size() << (d.layers.size() == 1 ? " layer" : " layers") << " (" << a.p.variant.name << ", "
       << img.width << "x" << img.height << " px) in " << std::fixed;
    hs.precision(2);
    hs << s["seconds"].get<double>() << " s";
    if (!a.out.preview.empty()) hs << "; preview " << a.out.preview;
    if (!a.terrain.empty()) hs << "; terrain " << a.terrain;
    report(a.out, s, hs.str());
  });
}

}  // namespace stipplot::cli
