#include "dualgrid/outputs/run_observers.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>

#include "dualgrid/core/text.hpp"
#include "dualgrid/outputs/figures.hpp"

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

void RunFilesObserver::OnStep(const cosim::StepView& v) {
  truth_.Write(v.frame);
  grid_.Write(v.pipeline);
  if (detections_) detections_->Write(v.pipeline);
  if (scans_) scans_->Write(v.pipeline);
  for (std::size_t m = 0; m < v.scorers.size(); ++m)
    clusters_.Write(v.frame, v.pipeline.grid_frame(), v.mode_names[m], v.scorers[m], v.objects,
                    v.pipeline.ids());
  if (!v.scorers.empty()) traces_.Add(v.pipeline, trace_mode_);
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
                                     std::vector<std::string>* warnings)
    : out_(out),
      every_(std::max(1, static_cast<int>(std::lround(interval_s / config.sim.step_length)))),
      step_count_(config.sim.StepCount()),
      max_particles_(max_particles),
      truth_label_(std::move(truth_label)),
      warnings_(warnings) {}

// Every every_-th step, and the last one (a run shorter than the interval still has a frame).
// Off for good once a recording write failed.
bool RecordingObserver::Due(int step) const {
  return !failed_ && ((step + 1) % every_ == 0 || step + 1 == step_count_);
}

bool RecordingObserver::WantsVelocities(int step, double) { return Due(step); }

void RecordingObserver::OnStep(const cosim::StepView& v) {
  if (counters_.empty())
    counters_.assign(v.scorers.size(),
                     replay::LiveCounter(v.pipeline.config().evaluation.tracking));
  live_.resize(v.scorers.size());
  // The live totals count every step, recorded or not.
  for (std::size_t m = 0; m < v.scorers.size(); ++m)
    live_[m] = counters_[m].Count(v.scorers[m], v.objects);
  if (!Due(v.step)) return;
  // The replay must never cost the run: a failed write (a full disk) stops the recording with a
  // warning; replay/ is then left without index.json, so it reads as unusable.
  try {
    if (!writer_) {
      header_ = replay::MakeHeader(v.pipeline, v.mode_names,
                                   every_ * v.pipeline.config().sim.step_length, max_particles_);
      header_.truth_label = truth_label_;
      writer_ = std::make_unique<replay::Writer>(out_ / "replay", header_);
    }
    writer_->Add(
        replay::Capture(v.pipeline, v.snapshots, v.scorers, counters_, live_, v.objects, header_));
    for (const auto& o : v.objects) ids_.insert(o.id);
  } catch (const std::exception& e) {
    warnings_->push_back(std::string("replay recording stopped: ") + e.what());
    std::cerr << "dualgrid: warning: " << warnings_->back() << "\n";
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
    warnings_->push_back(std::string("replay recording not written: ") + e.what());
    std::cerr << "dualgrid: warning: " << warnings_->back() << "\n";
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
                                 std::vector<std::string>* warnings)
    : out_(out),
      times_(std::move(times)),
      figures_(options.figures),
      particles_(options.write_particles),
      formats_(options.figure_formats),
      captions_(options.figure_captions),
      words_(WordsFor(options.references)),
      warnings_(warnings) {}

bool PictureObserver::WantsVelocities(int, double time) {
  // Several requested times may fall into one step: one picture for all of them.
  picture_ = false;
  while (next_ < times_.size() && time + 1e-9 >= times_[next_]) {
    picture_ = true;
    ++next_;
  }
  return picture_ && (figures_ || particles_);
}

void PictureObserver::OnStep(const cosim::StepView& v) {
  if (!picture_) return;
  const sim::Frame& f = v.frame;
  const std::string stamp = FormatFixed(f.time, 2);
  if (figures_) {
    TryFigures(
        out_ / "figures" / ("grid_t" + stamp + ".png"), formats_,
        [&](const auto& p) {
          RenderGridFigure(v.mode_names, v.snapshots, v.scorers, v.pipeline.grid_frame(), f, f.time,
                           p, captions_, words_);
        },
        warnings_);
    TryFigures(
        out_ / "figures" / ("scene_t" + stamp + ".png"), formats_,
        [&](const auto& p) { RenderScene(v.pipeline, p, 60, 140, 22, captions_, words_); },
        warnings_);
  }
  if (particles_)
    for (std::size_t m = 0; m < v.mode_names.size(); ++m)
      WriteParticles(v.pipeline, m, v.snapshots[m],
                     out_ / "figures" / ("particles_" + v.mode_names[m] + "_t" + stamp + ".csv"));
}

}  // namespace dualgrid::outputs
