// The interactive replay viewer's page (viz/viewer/viewer.html), compiled in. The page holds one
// placeholder, kViewerDataMarker, that the writer replaces with the recording (docs/replay.md).
#pragma once

#include <string_view>

namespace dualgrid::viz {

inline constexpr std::string_view kViewerDataMarker = "/*DUALGRID_DATA*/";

/// The page's text, placeholder included.
std::string_view ViewerTemplate();

}  // namespace dualgrid::viz
