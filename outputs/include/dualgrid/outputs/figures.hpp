// Pictures of a run, drawn with the viz library (cairo).
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "dualgrid/cosim/pipeline.hpp"
#include "dualgrid/cosim/scoring.hpp"
#include "dualgrid/eval/metrics.hpp"
#include "dualgrid/outputs/weight_traces.hpp"

namespace dualgrid::outputs {

/// Figures come after the results they show and never cost them: draws one figure and turns a
/// failure into a warning naming the file (printed to stderr and appended to `warnings`, which
/// the run records in summary.json). Returns whether the figure was written.
bool TryFigure(const std::filesystem::path& path, const std::function<void()>& draw,
               std::vector<std::string>* warnings);

/// Figure file formats: "png" (raster), "svg" and "pdf" (vectors, for papers).
inline const std::vector<std::string> kFigureFormats = {"png", "svg", "pdf"};

/// TryFigure once per format: `draw(path)` writes `path`, which is `png_path` with the format's
/// extension. Returns whether every format was written.
bool TryFigures(const std::filesystem::path& png_path, const std::vector<std::string>& formats,
                const std::function<void(const std::filesystem::path&)>& draw,
                std::vector<std::string>* warnings);

/// Bird's-eye picture of the current step: lanes, guard rails, parked boxes, vehicles, radar
/// fields of view and the step's detections with their radial-velocity arrows, drawn in the grid
/// frame (pipeline.grid_frame(): the world turned so that the grid's axes are the picture's). The
/// view spans [ego.x - behind, ego.x + ahead] x [ego.y - half_width, ego.y + half_width] there.
/// Every Render* below writes its caption under the figure unless `captions` is false
/// (`--figure-captions off`, for a paper that sets its own).
void RenderScene(const cosim::Pipeline& pipeline, const std::filesystem::path& path, double behind,
                 double ahead, double half_width, bool captions = true);

/// The paper's Fig. 7: one grid panel per mode at one time, ground-truth boxes outlined; in the
/// grid frame, whose axes are the grid's.
/// `scorers` hold each mode's clusters of this step (drawn with their roles and estimated
/// velocities beside the true velocities).
void RenderGridFigure(const std::vector<std::string>& modes,
                      const std::vector<cosim::GridSnapshot>& snapshots,
                      const std::vector<cosim::ModeScorer>& scorers, const GridFrame& grid_frame,
                      const sim::Frame& frame, double time, const std::filesystem::path& path,
                      bool captions = true);

/// D per object (name) and mode; NaN where a mode did not score the object.
using TrackedShares = std::vector<std::pair<std::string, std::vector<double>>>;

/// The paper's Fig. 6: tracked share (D or D_v, named by `y_label`) per object and mode; says
/// "no data" without objects. `errors`, when not empty, holds per object (same order as
/// `shares`) and mode the 95 % CI half-width over seeds, drawn as whiskers.
void RenderTrackedShares(const std::vector<std::string>& modes, const TrackedShares& shares,
                         const std::string& title, const std::string& y_label,
                         const std::filesystem::path& path, const TrackedShares& errors = {},
                         bool captions = true);

/// The scored objects' D (or D_v, `velocity_aware`) of one run, per mode (object ids named
/// through `ids`).
TrackedShares RunTrackedShares(const std::vector<eval::ScenarioMetrics>& metrics,
                               const cosim::IdRegistry& ids, bool velocity_aware);

/// The caption explains the shares for the run's `likelihood` (f_v of eq. (8)).
void RenderWeightTrace(const WeightTrace& trace, const std::string& object, const std::string& mode,
                       filter::VelocityLikelihood likelihood, const std::filesystem::path& path,
                       bool captions = true);

}  // namespace dualgrid::outputs
