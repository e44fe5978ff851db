#include "core/units.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <utility>

#include "core/errors.h"

namespace texlume {
namespace {}  // namespace

std::string ThreeSignificantDigits(double value) {
  if (!std::isfinite(value)) return "?";
  if (value == 0.0) return "0";
  const double scale = std::pow(10.0, 2.0 - std::floor(std::log10(std::abs(value))));
  const double rounded = std::round(value * scale) / scale;
  const int decimals = std::max(0, 2 - static_cast<int>(std::floor(std::log10(std::abs(rounded)))));
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, rounded);
  std::string out = text;
  if (out.find('.') != std::string::npos) {
    while (out.back() == '0') out.pop_back();
    if (out.back() == '.') out.pop_back();
  }
  return out;
}

double ParseLengthMm(const std::string& text, const std::string& option) {
  const auto refuse = [&] {
    throw OptionError(option + " '" + text +
                      "' is not a length (a number and a unit: um, mm, cm, m, in or ft, e.g. 1m)");
  };
  double value = 1.0;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  const char* number_end = first;
  if (!text.empty() && (std::isdigit(static_cast<unsigned char>(text[0])) || text[0] == '.')) {
    const std::from_chars_result read = std::from_chars(
        first, last, value, std::chars_format::fixed | std::chars_format::scientific);
    if (read.ec != std::errc()) refuse();
    number_end = read.ptr;
  }
  std::string unit(number_end, last);
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
  // The unit by the length as it is printed (999.7 mm reads "1 m").
  if (std::abs(mm) < 0.09995) return ThreeSignificantDigits(mm * 1e3) + " um";
  if (std::abs(mm) >= 999.5) return ThreeSignificantDigits(mm / 1e3) + " m";
  return ThreeSignificantDigits(mm) + " mm";
}

std::string WorldLengthText(double world_units, double mm_per_world_unit) {
  std::string text = ThreeSignificantDigits(world_units) + " world units";
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
