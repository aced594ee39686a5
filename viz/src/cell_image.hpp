// Private: a grid's cells as an image, one pixel per cell, shared by the grid figures and the
// replay video's frames (same colours, same placement).
#pragma once

#include <cairo.h>

#include "dualgrid/viz/grid_panels.hpp"
#include "dualgrid/viz/map_transform.hpp"

namespace dualgrid::viz::detail {

/// Fills `img` (CAIRO_FORMAT_RGB24, cells_x x cells_y, e.g. reused across frames) with
/// CellColor of every cell; image rows run down, grid rows up.
void FillCellImage(cairo_surface_t* img, const GridRaster& g, const CellColorOptions& options);

/// Paints `img` (from FillCellImage) where `t` puts the grid's cells, without smoothing: a cell
/// stays a sharp square at any scale. Clip to the map first.
void PaintCellImage(cairo_t* cr, const MapTransform& t, const GridRaster& g, cairo_surface_t* img);

}  // namespace dualgrid::viz::detail
