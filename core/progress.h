#pragma once

#include <cstddef>
#include <functional>
#include <string_view>

namespace texlume {

/// Reports progress of a long step: `done` of `total` units of the named stage.
/// Called from the calling thread only, a bounded number of times per step;
/// the program draws the bar (library code never prints).
using ProgressCallback =
    std::function<void(std::string_view stage, std::size_t done, std::size_t total)>;

}  // namespace texlume
