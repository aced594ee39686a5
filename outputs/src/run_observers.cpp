#include "dualgrid/outputs/run_observers.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/figures.hpp"

#include "pictures.hpp"

namespace dualgrid::outputs {

double ResidentMegabytes() {
  std::ifstream in("/proc/self/statm");
  long pages_total = 0, pages_resident = 0;
  if (!(in >> pages_total >> pages_resident)) return 0.0;
  return static_cast<double>(pages_resident) * static_cast<double>(sysconf(_SC_PAGE_SIZE)) / 1e6;
}

RunFilesObserver::RunFilesObserver(const std::filesystem::path& out,
                                   const std::optional<std::filesystem::path>& detections,
                                   bool multipath, std::size_t trace_mode, const std::string& focus,
                                   bool exact)
    : truth_(out / "ground_truth.csv"),
      grid_(out / "grid.csv"),
      clusters_(out / "clusters.csv"),
      trace_mode_(trace_mode),
      traces_(focus) {
  if (detections) detections_ = std::make_unique<DetectionWriter>(*detections, multipath, exact);
  if (detections && exact) scans_ = std::make_unique<ScanWriter>(out / "scans.csv");
}

void RunFilesObserver::Prepare(const cosim::StepView& v, Part part, int mode) {
  const auto m = static_cast<std::size_t>(mode);
  switch (part) {
    case Part::kStep:
      truth_.Write(v.frame);
      if (detections_) detections_->Write(v.pipeline);
      if (scans_) scans_->Write(v.pipeline);
      cluster_rows_.resize(v.scorers.size());
      return;
    case Part::kFiltered:
      if (m == trace_mode_) traces_.Add(v.pipeline, trace_mode_);
      return;
    case Part::kScored:
      cluster_rows_[m].clear();
      ClusterWriter::Rows(cluster_rows_[m], v.frame, v.pipeline.grid_frame(), v.mode_names[m],
                          v.scorers[m], v.objects, v.pipeline.ids());
      return;
  }
}

void RunFilesObserver::OnStep(const cosim::StepView& v) {
  // The grid's footprint reads the first filter: here, once every filter ran.
  grid_.Write(v.pipeline);
  for (std::size_t m = 0; m < v.scorers.size(); ++m) clusters_.Append(cluster_rows_[m]);
}

void RunFilesObserver::Close() {
  truth_.Close();
  grid_.Close();
  if (detections_) detections_->Close();
  if (scans_) scans_->Close();
  clusters_.Close();
}

RecordingObserver::RecordingObserver(const std::filesystem::path& out,
                                     const scenario::ScenarioConfig& config, double interval_s,
                                     int max_particles, std::string truth_label,
                                     std::vector<std::string>* warnings, OutputWorker& worker)
    : out_(out),
      every_(std::max(1, static_cast<int>(std::lround(interval_s / config.sim.step_length)))),
      step_count_(config.sim.StepCount()),
      max_particles_(max_particles),
      truth_label_(std::move(truth_label)),
      warnings_(warnings),
      worker_(worker) {}

RecordingObserver::~RecordingObserver() {
  if (!writer_) return;
  // A run ended by an error before Finish: a frame that failed in the background is still said.
  try {
    writer_->Flush();
  } catch (const std::exception& e) {
    PublishWarning(std::string("replay recording stopped: ") + e.what(), warnings_);
  }
}

// Every every_-th step, and the last one (a run shorter than the interval still has a frame).
// Off for good once a recording write failed.
bool RecordingObserver::Due(int step) const {
  return !failed_ && ((step + 1) % every_ == 0 || step + 1 == step_count_);
}

bool RecordingObserver::WantsVelocities(int step, double) { return Due(step); }

void RecordingObserver::Prepare(const cosim::StepView& v, Part part, int mode) {
  if (part == Part::kStep) {
    if (counters_.empty())
      counters_.assign(v.scorers.size(),
                       replay::LiveCounter(v.pipeline.config().evaluation.tracking));
    live_.resize(v.scorers.size());
    if (!Due(v.step)) return;
    capture_errors_.assign(1 + v.scorers.size(), nullptr);
    try {
      if (!header_made_) {
        header_ = replay::MakeHeader(v.pipeline, v.mode_names,
                                     every_ * v.pipeline.config().sim.step_length, max_particles_);
        header_.truth_label = truth_label_;
        header_made_ = true;
      }
      frame_ = replay::CaptureStep(v.pipeline, v.objects, v.scorers.size());
    } catch (...) {
      capture_errors_[0] = std::current_exception();
    }
    return;
  }
  if (part != Part::kScored) return;
  const auto m = static_cast<std::size_t>(mode);
  // The live totals count every step, recorded or not.
  live_[m] = counters_[m].Count(v.scorers[m], v.objects);
  if (!Due(v.step) || capture_errors_[0]) return;
  try {
    replay::CaptureMode(v.pipeline, m, v.snapshots[m], v.scorers[m], counters_[m], live_[m],
                        v.objects, header_, &frame_);
  } catch (...) {
    capture_errors_[1 + m] = std::current_exception();
  }
}

void RecordingObserver::OnStep(const cosim::StepView& v) {
  if (!Due(v.step)) return;
  // The replay must never cost the run: a failed write (a full disk) stops the recording with a
  // warning; replay/ is then left without index.json, so it reads as unusable. A frame that
  // could not be taken (Prepare) stops it the same way.
  try {
    for (const std::exception_ptr& e : capture_errors_)
      if (e) std::rethrow_exception(e);
    if (!writer_) writer_ = std::make_unique<replay::Writer>(out_ / "replay", header_, worker_);
    writer_->Add(std::move(frame_));
    for (const auto& o : v.objects) ids_.insert(o.id);
  } catch (const std::exception& e) {
    PublishWarning(std::string("replay recording stopped: ") + e.what(), warnings_);
    writer_.reset();
    failed_ = true;
  }
}

bool RecordingObserver::Finish(const nlohmann::json& metrics, const cosim::IdRegistry& ids,
                               bool complete, const std::string& status) {
  if (!writer_) return false;
  try {
    header_.metrics = metrics;
    for (int id : ids_) header_.names[std::to_string(id)] = ids.Name(id);
    header_.complete = complete;
    header_.status = status;
    writer_->Finish(header_);
    return true;
  } catch (const std::exception& e) {
    PublishWarning(std::string("replay recording not written: ") + e.what(), warnings_);
    writer_.reset();
    return false;
  }
}

void InvariantObserver::OnStep(const cosim::StepView& v) {
  for (std::size_t m = 0; m < v.pipeline.num_filters(); ++m)
    if (const auto broken = v.pipeline.grid(m).CheckInvariants())
      throw std::logic_error("filter invariant broken at t = " + FormatFixed(v.frame.time, 2) +
                             " s (" + v.mode_names[m] + "): " + *broken);
  if (v.step % std::max(1, static_cast<int>(std::lround(60.0 / step_length_))) == 0)
    rss_mb_.push_back({v.frame.time, ResidentMegabytes()});
}

nlohmann::json InvariantObserver::Samples(double end_time) const {
  nlohmann::json s = rss_mb_;
  s.push_back({end_time, ResidentMegabytes()});
  return s;
}

PictureObserver::PictureObserver(const std::filesystem::path& out, std::vector<double> times,
                                 const RunFolderOptions& options,
                                 std::vector<std::string>* warnings, OutputWorker& worker)
    : out_(out),
      times_(std::move(times)),
      figures_(options.figures),
      particles_(options.write_particles),
      formats_(options.figure_formats),
      captions_(options.figure_captions),
      words_(WordsFor(options.references)),
      warnings_(warnings),
      worker_(worker) {}

bool PictureObserver::WantsVelocities(int, double time) {
  // Several requested times may fall into one step: one picture for all of them.
  picture_ = false;
  while (next_ < times_.size() && time + 1e-9 >= times_[next_]) {
    picture_ = true;
    ++next_;
  }
  return picture_ && (figures_ || particles_);
}

// One step's grid and scene pictures, taken on the stepping thread and drawn by the worker. What
// could not be taken is drawn as a failure of every format, as drawing it in line would have.
struct PictureJob {
  std::filesystem::path grid_png, scene_png;
  std::vector<std::string> formats;
  std::optional<GridPicture> grid;
  std::optional<ScenePicture> scene;
  std::string grid_error, scene_error;
  std::vector<std::string> failures;  // filled by Draw, read once its future is ready

  void Draw() {
    failures = DrawFigures(grid_png, formats, [&](const std::filesystem::path& p) {
      if (!grid) throw std::runtime_error(grid_error);
      viz::RenderGridPanels(grid->panels, p.string(), grid->options);
    });
    const auto scene_failures =
        DrawFigures(scene_png, formats, [&](const std::filesystem::path& p) {
          if (!scene) throw std::runtime_error(scene_error);
          DrawScene(*scene, p);
        });
    failures.insert(failures.end(), scene_failures.begin(), scene_failures.end());
  }
};

void PictureObserver::OnStep(const cosim::StepView& v) {
  if (!picture_) return;
  // The previous picture's warnings now, at a point that does not depend on the worker's speed:
  // the warnings' order is the same on one thread and on two.
  Publish();
  const sim::Frame& f = v.frame;
  const std::string stamp = FormatFixed(f.time, 2);
  if (figures_) {
    auto job = std::make_shared<PictureJob>();
    job->grid_png = out_ / "figures" / ("grid_t" + stamp + ".png");
    job->scene_png = out_ / "figures" / ("scene_t" + stamp + ".png");
    job->formats = formats_;
    try {
      job->grid = MakeGridFigure(v.mode_names, v.snapshots, v.scorers, v.pipeline.grid_frame(), f,
                                 f.time, captions_, words_);
    } catch (const std::exception& e) {
      job->grid_error = e.what();
    }
    try {
      job->scene = MakeScene(v.pipeline, 60, 140, 22, captions_, words_);
    } catch (const std::exception& e) {
      job->scene_error = e.what();
    }
    pending_.push_back({worker_.Post([job] { job->Draw(); }), job});
  }
  if (particles_)
    for (std::size_t m = 0; m < v.mode_names.size(); ++m)
      WriteParticles(v.pipeline, m, v.snapshots[m],
                     out_ / "figures" / ("particles_" + v.mode_names[m] + "_t" + stamp + ".csv"));
}

PictureObserver::~PictureObserver() {
  // A run that ends by an error still reports its pictures' failures before that error, as
  // drawing them in line did.
  try {
    Publish();
  } catch (...) {  // NOLINT(bugprone-empty-catch): the run's own error is on its way
  }
}

void PictureObserver::Finish() { Publish(); }

void PictureObserver::Publish() {
  while (!pending_.empty()) {
    auto& [done, job] = pending_.front();
    done.get();  // DrawFigures catches what a figure throws; anything else is the run's error
    for (const std::string& failure : job->failures) PublishWarning(failure, warnings_);
    pending_.pop_front();
  }
}

}  // namespace dualgrid::outputs
