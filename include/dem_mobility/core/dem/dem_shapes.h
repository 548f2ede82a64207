// Rigid tool and container shapes for the DEM soil, as walls (body frame, z up). A particle touches
// a wall at its deepest triangle, so a wall must be flat or convex: a concave container is built
// of several flat walls.
#pragma once

#include <string>
#include <vector>

#include "dem_mobility/core/dem/dem_system.h"

namespace dem_mobility::core {

/// An open box [0, length] x [0, width] x [0, height]: a floor and four sides, each a flat wall
/// (floor, x0, x1, y0, y1).
std::vector<DemWall> MakeOpenBoxWalls(double length, double width, double height);

/// A flat disk of `segments` triangles about the body origin in the x-y plane (a floor or a lid).
DemWall MakeDiskWall(const std::string& name, double radius, int segments);

/// The side of a vertical cylinder (axis z, from z = 0 to `height`) as `segments` flat walls, one
/// per facet. The facets' inscribed radius is `radius`, so no particle inside the radius is cut.
std::vector<DemWall> MakeCylinderSideWalls(const std::string& name, double radius, double height, int segments);

/// A cone with its tip at the body origin pointing down (-z) and its base, a closed disk, at
/// z = `length` with radius `base_radius` (convex: one wall).
DemWall MakeConeWall(const std::string& name, double base_radius, double length, int segments);

/// A closed vertical rod (a prism of `segments` sides, capped) from z = 0 to `length` (convex).
DemWall MakeRodWall(const std::string& name, double radius, double length, int segments);

}  // namespace dem_mobility::core
