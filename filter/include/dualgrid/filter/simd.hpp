// The SIMD target the filter's vector kernels were built for (Highway, one static target per
// build: docs/performance.md, "Issue 37"). Results are the same on every CPU that runs the build.
#pragma once

namespace dualgrid::filter {

/// Highway's name of the target, e.g. "SSE4" on x86-64.
const char* SimdTarget();

}  // namespace dualgrid::filter
