#include "core/units.h"

#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/errors.h"

namespace texlume {
namespace {

std::string Significant3(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

}  // namespace

double ParseLengthMm(const std::string& text, const std::string& option) {
  const auto refuse = [&] {
    throw OptionError(option + " '" + text +
                      "' is not a length (a number and a unit: um, mm, cm, m, in or ft, e.g. 1m)");
  };
  std::size_t used = 0;
  double value = 1.0;
  const bool starts_with_number =
      !text.empty() && (std::isdigit(static_cast<unsigned char>(text[0])) || text[0] == '.');
  if (starts_with_number) {
    try {
      value = std::stod(text, &used);
    } catch (const std::exception&) {
      refuse();
    }
  }
  std::string unit = text.substr(used);
  while (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
  constexpr std::array<std::pair<const char*, double>, 7> kMmPerUnit = {{{"um", 1e-3},
                                                                         {"\u00b5m", 1e-3},
                                                                         {"mm", 1.0},
                                                                         {"cm", 10.0},
                                                                         {"m", 1000.0},
                                                                         {"in", 25.4},
                                                                         {"ft", 304.8}}};
  for (const auto& [name, mm] : kMmPerUnit) {
    if (unit != name) continue;
    const double length_mm = value * mm;
    if (!(length_mm >= 1e-6 && length_mm <= 1e9)) refuse();
    return length_mm;
  }
  refuse();
  return 0.0;
}

std::string MillimetreText(double mm) {
  if (std::abs(mm) < 0.1) return Significant3(mm * 1e3) + " um";
  if (std::abs(mm) >= 1000.0) return Significant3(mm / 1e3) + " m";
  return Significant3(mm) + " mm";
}

std::string WorldLengthText(double world_units, double mm_per_world_unit) {
  std::string text = Significant3(world_units) + " world units";
  if (mm_per_world_unit > 0.0) text += " (" + MillimetreText(world_units * mm_per_world_unit) + ")";
  return text;
}

double NiceLengthAtMost(double at_most) {
  if (!(at_most > 0.0) || !std::isfinite(at_most)) return 0.0;
  const double decade = std::pow(10.0, std::floor(std::log10(at_most)));
  for (const double step : {5.0, 2.0, 1.0})
    if (step * decade <= at_most * (1.0 + 1e-12)) return step * decade;
  return decade;
}

}  // namespace texlume
