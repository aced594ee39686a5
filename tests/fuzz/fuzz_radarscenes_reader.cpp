// libFuzzer target for the RadarScenes reader (recorded/src/radarscenes_read.cpp): the input is
// sensors.json and scenes.json joined by a line "@@@"; radar_data.h5 is a fixed small file
// written once by dualgrid's writer (libhdf5's own parsing is not ours to fuzz). Every input must
// be read or refused with std::invalid_argument; any other exception, a crash, a hang or a
// sanitizer report is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "dualgrid/recorded/radarscenes.hpp"
#include "fuzz_files.hpp"

namespace {

// A dataset root with one sequence of two scans of one sensor, three detections each.
void WriteFixedData() {
  using namespace dualgrid;
  recorded::RecordedSequence seq;
  seq.name = "sequence_1";
  radar::SensorParams s;
  s.name = "radar_1";
  seq.sensors = {s};
  for (int k = 0; k < 2; ++k) {
    recorded::RecordedScan scan;
    scan.timestamp_us = 1000000 + 50000 * k;
    scan.begin = seq.points.size();
    for (int i = 0; i < 3; ++i) {
      recorded::RecordedPoint p;
      p.range = 10.0 + i;
      p.position = {10.0 + i, 1.0};
      p.label = i == 0 ? 0 : recorded::kStaticLabel;
      seq.points.push_back(p);
    }
    scan.end = seq.points.size();
    seq.scans.push_back(scan);
  }
  seq.has_labels = true;
  seq.time_origin_us = 1000000;
  recorded::WriteRadarScenes(seq, dualgrid::fuzz::Folder(), 1.45);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool written = (WriteFixedData(), true);
  (void)written;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  dualgrid::fuzz::WriteParts(input, {"sensors.json", "data/sequence_1/scenes.json"});
  try {
    (void)dualgrid::recorded::ReadRadarScenes(dualgrid::fuzz::Folder() / "data" / "sequence_1",
                                              std::nullopt);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
