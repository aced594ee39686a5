// Dynamic occupancy grid pictures (paper Fig. 7): one panel per filter mode, stacked or side by
// side, laid out in points at a column width (dualgrid/viz/figure.hpp).
#pragma once

#include <string>
#include <vector>

#include "dualgrid/core/types.hpp"
#include "dualgrid/viz/color.hpp"
#include "dualgrid/viz/figure.hpp"
#include "dualgrid/viz/map_transform.hpp"

namespace dualgrid::viz {

/// Cell masses and mean velocities of a grid, axis-aligned with the world frame.
struct GridRaster {
  int cells_x = 0;
  int cells_y = 0;
  double resolution = 0.0;             ///< cell edge [m]
  Position origin = Position::Zero();  ///< world position of the lower-left corner of cell (0,0)
  /// Row-major, index = y * cells_x + x, x along world +x, y along world +y.
  std::vector<float> free, static_occ, dynamic, mean_vx, mean_vy;

  /// World rectangle covered by the grid.
  WorldRect Extent() const;
  /// False (error names the field) for non-positive sizes or arrays not of cells_x * cells_y.
  bool IsValid(std::string* error) const;
};

enum class CellColoring {
  /// colour = free*white + static*black + dynamic*HueColor(atan2(vy, vx)) + unknown*grey, with
  /// unknown = 1 - free - static - dynamic (clamped at 0; masses renormalised if they sum above 1).
  /// Continuous, so weak dynamic mass shows as a faint tint.
  kBlend,
  /// Cells with dynamic > dynamic_threshold are pure HueColor; others use the blend above with
  /// their dynamic mass counted as unknown (the paper's classification, threshold 0.6).
  kThreshold,
};

struct CellColorOptions {
  CellColoring coloring = CellColoring::kBlend;
  double dynamic_threshold = 0.6;
  bool IsValid(std::string* error) const;
};

/// Colour of one cell (see CellColoring). Negative masses count as 0.
Rgba CellColor(float free, float static_occ, float dynamic, float vx, float vy,
               const CellColorOptions& options = {});

/// A cluster of dynamic particles (the scorer's, docs/evaluation.md): its members' bounding box
/// [m], mean position [m] and estimated velocity over ground [m/s], drawn as an outline in its
/// role's colour (ClusterRoleColor) with a velocity arrow.
struct GridCluster {
  Position min = Position::Zero(), max = Position::Zero(), center = Position::Zero();
  Velocity velocity = Velocity::Zero();
  int role = 0;  ///< 0 matched to an object, 1 duplicate, 2 false
};

struct GridPanel {
  std::string title;  ///< e.g. "position", "velocity", "dual"
  GridRaster raster;
  std::vector<OrientedBox> truth_boxes;  ///< ground-truth outlines (black on a white halo)
  /// Optional: one per truth box, its true velocity [m/s], drawn as a black arrow.
  std::vector<Velocity> truth_velocities;
  std::vector<GridCluster> clusters;   ///< optional estimated objects
  std::vector<Position> particles;     ///< optional, drawn as tiny dots
  std::vector<OrientedBox> ego_boxes;  ///< optional ego outline(s), drawn green
};

struct GridFigureOptions {
  /// Whole image width [pt] (PNG: times png_scale): left axis margin + panels; the legend band
  /// and caption go underneath.
  int image_width = static_cast<int>(kSingleColumn);
  std::string title;           ///< figure title above all panels when not empty
  double arrow_seconds = 0.5;  ///< a velocity arrow is this many seconds of motion [s]
  /// Wrapped under the legend when not empty: what the colours, outlines and axes mean.
  std::string caption;
  CellColorOptions cell;
  /// Base font size [pt]; 0: BaseFontSize(image_width), readable at one column (the smallest
  /// text is 0.9 of it).
  double font_size = 0.0;
  /// Axis labels (the frame and origin of the rasters' coordinates, e.g. relative to the ego).
  std::string x_label = "x [m]", y_label = "y [m]";
  /// The legend's name for the reference boxes (e.g. "annotated" for a data set's boxes).
  std::string truth_label = "ground truth";
  /// Panels per row: 0 = automatic (side by side when a panel is at most 2.5 times as wide as
  /// high, e.g. a square grid; stacked for the paper's 8:1 road grid), else 1..panels.
  int columns = 0;
  double png_scale = kPngScale;  ///< PNG pixels per point
  bool IsValid(std::string* error) const;
  /// font_size, or the automatic one.
  double BaseFont() const;
};

/// Where each panel's map lands in the image (exposed so callers and tests can locate cells).
struct GridFigureLayout {
  int width = 0;
  int height = 0;
  std::vector<MapTransform> panels;  ///< with pixel offsets into the image
};

/// Throws std::invalid_argument (naming e.g. "panels[1].raster.dynamic") for bad input.
GridFigureLayout LayoutGridPanels(const std::vector<GridPanel>& panels,
                                  const GridFigureOptions& options = {});

/// Renders the panels stacked or side by side (options.columns), each with its title and axes in
/// metres (stacked panels share the x labels, side by side ones the y labels), then a legend band
/// (hue wheel for the direction of motion, free/static/unknown swatches, outlines) and the
/// caption.
/// Throws std::invalid_argument for bad input, std::runtime_error if the PNG cannot be written.
/// `path` ends in .png, .svg or .pdf (the cells are an embedded raster in SVG and PDF).
void RenderGridPanels(const std::vector<GridPanel>& panels, const std::string& path,
                      const GridFigureOptions& options = {});

}  // namespace dualgrid::viz
