// libFuzzer target for the nuScenes reader (recorded/src/nuscenes_*.cpp, pcd.cpp): the input is
// the tables scene, sample, sample_data, calibrated_sensor, ego_pose, sample_annotation,
// instance, category and sensor (v1.0-mini/NAME.json), dualgrid.json and one PCD file
// (samples/RADAR_FRONT/a.pcd), in that order, joined by lines "@@@". Every input must be read or
// refused with std::invalid_argument; any other exception, a crash, a hang or a sanitizer report
// is a bug.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "dualgrid/recorded/nuscenes.hpp"
#include "dualgrid/recorded/pcd.hpp"
#include "fuzz_files.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::string v = "v1.0-mini/";
  dualgrid::fuzz::WriteParts(
      input,
      {v + "scene.json", v + "sample.json", v + "sample_data.json", v + "calibrated_sensor.json",
       v + "ego_pose.json", v + "sample_annotation.json", v + "instance.json", v + "category.json",
       v + "sensor.json", v + "dualgrid.json", "samples/RADAR_FRONT/a.pcd"});
  try {
    (void)dualgrid::recorded::ReadPcd(dualgrid::fuzz::Folder() / "samples/RADAR_FRONT/a.pcd");
  } catch (const std::invalid_argument&) {
  }
  try {
    dualgrid::recorded::NuScenesOptions o;
    o.scene = "scene-test";
    (void)dualgrid::recorded::ReadNuScenes(dualgrid::fuzz::Folder(), o);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
