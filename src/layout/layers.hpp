#pragma once
// Choosing layers and pens, as AxiDraw and vpype users do: plot some layers only, and say
// which pen draws which layer. A layer is named by its position in the drawing (1, 2,
// ...), by its name (an Inkscape layer's label without its leading number), or, for the
// pen map, by its pen colour as the SVG gives it (#rrggbb, #rgb or an SVG colour name).
// Layers given the same pen are drawn with it one after the other (the planner merges
// them); the writers plan reloads when there are more pens than the machine holds.
#include <string>

#include "geometry/drawing.hpp"

namespace stipplot::layout {

// "--layer 1,3,outline": keeps the layers named, in drawing order. Every pen gets its
// number first (resolve_pen_numbers), so the layers kept go to the pens they would have
// had. Throws UserError naming an item that matches no layer, with the layers there are.
// O(layers x items).
void keep_layers(Drawing& d, const std::string& selection);

// "--pen-map red=2,#0000ff=3,1=1,outline=4": sets the pen number of every layer an item
// names (a position, else a name, else a colour); layers it names none of get the lowest
// numbers it leaves free. Throws UserError naming a malformed or unmatched item.
// O(layers x items).
void apply_pen_map(Drawing& d, const std::string& map);

}  // namespace stipplot::layout
