// The ground of `farfield gen city --terrain SPEC` and `farfield path street --terrain SPEC`: a DEM file or a
// "fractal:..." spec (farfield/terrain) laid under the city, its centre under the centre of the street graph, heights
// relative to the terrain's height there, times a vertical scale. Beyond the terrain's edge the edge's heights go on.
#pragma once

#include <string>

#include "farfield/gen/city.h"

namespace farfield::app {

// Sets options.ground and options.ground_cell (half the terrain's cell size) from the terrain `spec`, and returns a
// line describing the terrain. Throws farfield::Error for a bad spec or file, or a scale that is not a finite number > 0.
std::string setCityTerrain(gen::CityOptions& options, const std::string& spec, float vertical_scale);

}  // namespace farfield::app
