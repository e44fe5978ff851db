#pragma once

#include <string>

namespace texlume {

/// Parses a physical length: a positive number followed by a unit, "1m", "2.5 cm",
/// "25.4mm", "0.5in", "1ft", or a unit alone ("m" = 1 m). Units: um or µm (micrometres), mm,
/// cm, m, in, ft. Returns millimetres. Throws OptionError naming `option` for anything
/// else, for zero, and for lengths outside [1 nm, 1000 km].
double ParseLengthMm(const std::string& text, const std::string& option);

/// A length given in world units as the report and the manifest show it: "0.00391 world
/// units", and when one world unit's length is known (`mm_per_world_unit` > 0), " (0.391 mm)"
/// after it, in um, mm or m whichever reads best. Three significant digits.
std::string WorldLengthText(double world_units, double mm_per_world_unit);

/// A length in millimetres in um, mm or m whichever reads best, three significant digits:
/// "391 um", "3.91 mm", "1.2 m".
std::string MillimetreText(double mm);

/// A number to three significant digits, without an exponent or trailing zeros: "0.00391",
/// "1.2", "1000", "1230000"; "?" when not finite.
std::string ThreeSignificantDigits(double value);

/// The "nice" length (1, 2 or 5 times a power of ten) closest below `at_most`, > 0.
double NiceLengthAtMost(double at_most);

}  // namespace texlume
