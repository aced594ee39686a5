#include "dualgrid/outputs/video.hpp"

#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "dualgrid/core/text.hpp"
#include "dualgrid/viz/color.hpp"
#include "dualgrid/viz/replay_frame.hpp"

namespace dualgrid::outputs {

namespace fs = std::filesystem;

const fs::path& CheckOutputFile(const fs::path& path, const std::string& option,
                                const std::string& extension) {
  if (path.extension() != extension)
    throw std::invalid_argument(option + ": expected a " + extension + " file, got " +
                                path.string());
  if (!fs::is_directory(fs::absolute(path).parent_path()))
    throw std::invalid_argument(option + ": folder " + fs::absolute(path).parent_path().string() +
                                " does not exist");
  return path;
}

std::optional<fs::path> FindFfmpeg() {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const fs::path p = fs::path(dir.empty() ? "." : dir) / "ffmpeg";
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  return std::nullopt;
}

std::pair<std::size_t, std::size_t> FrameRange(const replay::Reader& reader,
                                               const ReplayOptions& o) {
  if (o.from < 0.0 || o.to < 0.0 || (o.to > 0.0 && o.to < o.from))
    throw std::invalid_argument("--from/--to: expected 0 <= from <= to (to = 0: the end), got " +
                                FormatFixed(o.from, 2) + " and " + FormatFixed(o.to, 2));
  std::size_t first = reader.size(), last = 0;
  for (std::size_t i = 0; i < reader.size(); ++i) {
    const double t = reader.time(i);
    if (t + 1e-9 < o.from || (o.to > 0.0 && t > o.to + 1e-9)) continue;
    first = std::min(first, i);
    last = i + 1;
  }
  if (first >= last)
    throw std::invalid_argument("--from/--to: no recorded frame in [" + FormatFixed(o.from, 2) +
                                ", " + (o.to > 0.0 ? FormatFixed(o.to, 2) : std::string("end")) +
                                "] s (" + std::to_string(reader.size()) + " frames recorded" +
                                (reader.size()
                                     ? ", " + FormatFixed(reader.time(0), 2) + " to " +
                                           FormatFixed(reader.time(reader.size() - 1), 2) + " s"
                                     : std::string()) +
                                ")");
  return {first, last};
}

std::vector<std::size_t> SelectModes(const replay::Header& h, const ReplayOptions& o) {
  std::vector<std::size_t> out;
  if (o.modes.empty()) {
    for (std::size_t m = 0; m < h.modes.size(); ++m) out.push_back(m);
    return out;
  }
  for (const std::string& name : o.modes) {
    const auto it = std::find(h.modes.begin(), h.modes.end(), name);
    if (it == h.modes.end()) {
      std::string recorded;
      for (const auto& m : h.modes) recorded += (recorded.empty() ? "" : ", ") + m;
      throw std::invalid_argument("--modes: '" + name +
                                  "' was not recorded (recorded: " + recorded + ")");
    }
    out.push_back(static_cast<std::size_t>(it - h.modes.begin()));
  }
  return out;
}

namespace {

// ffmpeg reading raw frames on its standard input; its output and messages go to a log file.
class FfmpegPipe {
 public:
  FfmpegPipe(std::vector<std::string> args, const fs::path& log) : log_(log) {
    int fds[2];
    // Close-on-exec: ffmpeg inherits only its stdin, not this process's other files.
    if (pipe2(fds, O_CLOEXEC) != 0)
      throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const std::string log_path = log.string();
    pid_ = fork();
    if (pid_ < 0) {
      const int err = errno;
      close(fds[0]);
      close(fds[1]);
      throw std::runtime_error(std::string("cannot start ffmpeg: ") + std::strerror(err));
    }
    if (pid_ == 0) {
      // Its own process group: Ctrl-C reaches dualgrid, which stops ffmpeg and removes the
      // unfinished file, instead of ffmpeg dying first and looking like a failure.
      setpgid(0, 0);
      prctl(PR_SET_PDEATHSIG, SIGTERM);
      dup2(fds[0], 0);
      close(fds[0]);
      close(fds[1]);
      int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0) fd = open("/dev/null", O_WRONLY);
      if (fd >= 0) {
        dup2(fd, 1);
        dup2(fd, 2);
        close(fd);
      }
      execv(argv[0], argv.data());
      _exit(127);
    }
    close(fds[0]);
    fd_ = fds[1];
  }
  ~FfmpegPipe() { Kill(); }
  /// Stops ffmpeg without waiting for its output (on an error).
  void Kill() {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
    if (pid_ > 0) {
      kill(pid_, SIGTERM);
      while (waitpid(pid_, nullptr, 0) < 0 && errno == EINTR) {
      }
    }
    pid_ = -1;
  }
  /// False when ffmpeg stopped reading (it failed; see Close()).
  bool Write(const std::uint8_t* data, std::size_t n) {
    while (n > 0) {
      const ssize_t k = write(fd_, data, n);
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) return false;
      data += k;
      n -= static_cast<std::size_t>(k);
    }
    return true;
  }
  /// Ends the input and waits; throws naming the log when ffmpeg failed.
  void Close() {
    close(fd_);
    fd_ = -1;
    int status = 0;
    pid_t r;
    while ((r = waitpid(pid_, &status, 0)) < 0 && errno == EINTR) {
    }
    pid_ = -1;
    if (r < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
      throw std::runtime_error("ffmpeg failed (" + LastLine() + "); its log: " + log_.string());
  }

 private:
  std::string LastLine() const {
    std::ifstream in(log_);
    std::string line, last = "no message";
    while (std::getline(in, line))
      if (!line.empty()) last = line;
    return last;
  }
  fs::path log_;
  pid_t pid_ = -1;
  int fd_ = -1;
};

void RunFfmpeg(const std::vector<std::string>& args, const fs::path& log) {
  FfmpegPipe p(args, log);
  p.Close();
}

// The recorded frame as the renderer's picture: positions relative to the ego.
viz::ReplayPicture ToPicture(const replay::Reader& reader, const replay::Frame& f,
                             const std::vector<std::size_t>& modes, const ReplayOptions& o) {
  const replay::Header& h = reader.header();
  const Position ego(f.ego.x, f.ego.y);
  // Returns Position, not auto: an Eigen expression would refer to a destroyed temporary.
  const auto rel = [&](double x, double y) -> Position { return Position(x, y) - ego; };
  viz::ReplayPicture pic;
  pic.heading = h.scenario + " \u00b7 seed " + std::to_string(h.seed);
  pic.time = f.time;
  pic.ego = {Position::Zero(), f.ego.yaw, f.ego.length, f.ego.width};
  if (!h.complete) pic.banner = "INCOMPLETE RUN";
  if (o.detections) {
    for (const auto& d : f.detections) pic.detections.push_back({rel(d.x, d.y), d.sensor});
  }
  const std::size_t n = static_cast<std::size_t>(h.cells_x) * h.cells_y;
  for (const std::size_t m : modes) {
    const replay::ModeFrame& mf = f.modes[m];
    viz::ReplayPanel p;
    p.title = h.modes[m];
    const replay::Live& l = mf.live;
    const auto pct = [](long a, long b) {
      return b > 0 ? FormatFixed(100.0 * a / b, 0) + " %" : std::string("-");
    };
    p.live = "in grid " + std::to_string(l.in_grid) + " \u00b7 tracked " +
             std::to_string(l.tracked) + " \u00b7 right velocity " + std::to_string(l.tracked_v) +
             " \u00b7 false " + std::to_string(l.false_clusters) + "   so far: tracked " +
             pct(l.total_tracked, l.total_in_grid) + ", right velocity " +
             pct(l.total_tracked_v, l.total_in_grid);
    viz::GridRaster& r = p.raster;
    r.cells_x = h.cells_x;
    r.cells_y = h.cells_y;
    r.resolution = h.resolution;
    r.origin = rel(f.origin_x, f.origin_y);
    r.free.resize(n);
    r.static_occ.resize(n);
    r.dynamic.resize(n);
    r.mean_vx.resize(n);
    r.mean_vy.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      r.free[k] = mf.free[k] / 255.0f;
      r.static_occ[k] = mf.static_occ[k] / 255.0f;
      r.dynamic[k] = mf.dynamic[k] / 255.0f;
      r.mean_vx[k] = mf.vx_cm[k] / 100.0f;
      r.mean_vy[k] = mf.vy_cm[k] / 100.0f;
    }
    for (const auto& b : f.truth) {
      p.truth.push_back({rel(b.x, b.y), b.yaw, b.length, b.width});
      p.truth_velocity.emplace_back(b.vx, b.vy);
    }
    for (const auto& c : mf.clusters)
      p.clusters.push_back({rel(c.min_x, c.min_y), rel(c.max_x, c.max_y), rel(c.x, c.y),
                            Velocity(c.vx, c.vy), c.role});
    if (o.particles)
      for (std::size_t k = 0; k + 1 < mf.particles.size(); k += 2)
        p.particles.push_back(rel(f.origin_x + mf.particles[k] * h.particle_unit,
                                  f.origin_y + mf.particles[k + 1] * h.particle_unit));
    pic.panels.push_back(std::move(p));
  }
  return pic;
}

// The renderer's layout: the view fixed relative to the ego (the grid as placed at the first
// frame), one panel per mode. Errors name the option a user can change.
viz::ReplayLayoutOptions Layout(const replay::Header& h, const replay::Frame& first_frame,
                                std::size_t modes, const ReplayOptions& o) {
  viz::ReplayLayoutOptions layout;
  layout.width = o.width;
  // The view stays fixed relative to the ego: the grid as placed at the first frame.
  const Position lo =
      Position(first_frame.origin_x - first_frame.ego.x, first_frame.origin_y - first_frame.ego.y);
  layout.view = {lo, lo + Vector2(h.cells_x * h.resolution, h.cells_y * h.resolution)};
  layout.panels = static_cast<int>(modes);
  if (o.detections) layout.sensors = h.sensors;
  layout.particles = o.particles;
  layout.truth_label = h.truth_label;
  try {
    layout.Validate();
  } catch (const std::invalid_argument& e) {
    // Name the option a user can change: --width for the width, --modes for the panel count.
    const std::string what = e.what();
    throw std::invalid_argument(what.rfind("width", 0) == 0    ? "--" + what
                                : what.rfind("panels", 0) == 0 ? "--modes: " + what
                                                               : "replay: " + what);
  }
  return layout;
}

// ffmpeg's arguments for raw BGRA frames of `width` x `height` at `fps` into an H.264 MP4 `part`.
// yuv420p: the pixel format every player decodes; +faststart: playable while downloading.
std::vector<std::string> EncoderArgs(const fs::path& ffmpeg, int width, int height, double fps,
                                     const fs::path& part) {
  return {ffmpeg.string(),
          "-hide_banner",
          "-nostdin",
          "-loglevel",
          "error",
          "-y",
          "-f",
          "rawvideo",
          "-pix_fmt",
          "bgra",
          "-s",
          std::to_string(width) + "x" + std::to_string(height),
          "-framerate",
          FormatSignificant(fps, 17),
          "-i",
          "-",
          "-c:v",
          "libx264",
          "-preset",
          "veryfast",
          "-crf",
          "23",
          "-pix_fmt",
          "yuv420p",
          "-movflags",
          "+faststart",
          "-f",
          "mp4",
          part.string()};
}

// The preview beside the video (replay_preview.gif/.webm): the run at 4x, 480 px wide, 6
// frames/s, at most 15 s.
void WritePreview(const fs::path& ffmpeg, const fs::path& out, const std::string& format,
                  const fs::path& log) {
  const fs::path preview = out.parent_path() / (out.stem().string() + "_preview." + format);
  const fs::path preview_part = fs::path(preview).concat(".part");
  // The run at 4x, 480 px wide, 6 frames/s, at most 15 s (the first minute of the run): a
  // few MB (the cells' noise defeats GIF's compression; fewer colours and no dithering help).
  std::vector<std::string> args = {
      ffmpeg.string(), "-hide_banner", "-nostdin", "-loglevel", "error", "-y", "-i",
      out.string(),    "-t",           "15"};
  if (format == "gif")
    args.insert(args.end(), {"-vf",
                             "setpts=PTS/4,fps=6,scale=480:-2:flags=lanczos,split[a][b];"
                             "[a]palettegen=max_colors=64[p];[b][p]paletteuse=dither=none",
                             "-loop", "0", "-f", "gif"});
  else
    args.insert(args.end(), {"-vf", "setpts=PTS/4,fps=6,scale=480:-2", "-c:v", "libvpx-vp9", "-b:v",
                             "0", "-crf", "40", "-deadline", "realtime", "-f", "webm"});
  args.push_back(preview_part.string());
  try {
    RunFfmpeg(args, log);
  } catch (const std::exception& e) {
    fs::remove(preview_part);
    throw std::runtime_error(std::string(e.what()) + " (the video itself, " + out.string() +
                             ", is complete)");
  }
  fs::rename(preview_part, preview);
}

}  // namespace

fs::path WriteVideo(const replay::Reader& reader, const ReplayOptions& o,
                    const Callbacks& callbacks) {
  if (o.preview != "gif" && o.preview != "webm" && o.preview != "none")
    throw std::invalid_argument("--preview: expected gif, webm or none, got '" + o.preview + "'");
  if (!(o.speed >= 0.1 && o.speed <= 20.0))
    throw std::invalid_argument("--speed: expected 0.1 to 20, got " + FormatFixed(o.speed, 2));
  const fs::path out = CheckOutputFile(
      o.out.empty() ? reader.dir().parent_path() / "replay.mp4" : o.out, "--out", ".mp4");
  const auto [first, last] = FrameRange(reader, o);
  const std::vector<std::size_t> modes = SelectModes(reader.header(), o);
  const auto ffmpeg = FindFfmpeg();
  if (!ffmpeg)
    throw std::runtime_error(
        "ffmpeg not found on PATH; the video needs Debian's ffmpeg (apt-get install ffmpeg)");

  const replay::Header& h = reader.header();
  const replay::Frame first_frame = reader.Load(first);
  viz::ReplayRenderer renderer(Layout(h, first_frame, modes.size(), o));
  const fs::path part = fs::path(out).concat(".part");
  const fs::path log = fs::path(out).replace_extension(".ffmpeg.log");
  FfmpegPipe pipe(
      EncoderArgs(*ffmpeg, renderer.width(), renderer.height(), o.speed / h.interval, part), log);
  callbacks.Begin("replay video " + out.filename().string(), static_cast<int>(last - first));
  const std::size_t bytes = static_cast<std::size_t>(renderer.width()) * renderer.height() * 4;
  try {
    for (std::size_t i = first; i < last; ++i) {
      if (callbacks.StopRequested()) throw Stopped();
      const replay::Frame f = i == first ? first_frame : reader.Load(i);
      const std::uint8_t* raster = renderer.Render(ToPicture(reader, f, modes, o));
      if (!pipe.Write(raster, bytes)) break;  // ffmpeg stopped: Close() reports why
      callbacks.Progress(static_cast<int>(i - first + 1), "t=" + FormatFixed(f.time, 1) + " s");
    }
    callbacks.End();
    pipe.Close();
  } catch (...) {
    pipe.Kill();
    fs::remove(part);  // a video that did not finish must not stay behind looking like one
    throw;
  }
  fs::rename(part, out);

  if (o.preview != "none") WritePreview(*ffmpeg, out, o.preview, log);
  fs::remove(log);
  return out;
}

}  // namespace dualgrid::outputs
