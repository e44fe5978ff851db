#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <map>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets_synthetic/material.h"
#include "datasets_synthetic/photo_sensor.h"
#include "datasets_synthetic/shapes.h"

namespace texlume::apps {

/// What each subcommand does once the command line is parsed: runs its job
/// with the Options its options were bound to, and returns the exit code.
using CommandRunners =
    std::map<const CLI::App*, std::function<int(std::ostream& out, std::ostream& err)>>;

/// A command line that does not fit the subcommand (exit code 2).
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Each adds one subcommand to `app`, binds its options to the job's Options
/// (help text and default from the binding) and registers its runner.
void AddInspectCommand(CLI::App& app, CommandRunners& run);
void AddFitCommand(CLI::App& app, CommandRunners& run);
void AddBtfCommand(CLI::App& app, CommandRunners& run);
void AddRelightCommand(CLI::App& app, CommandRunners& run);
void AddLightsFromSphereCommand(CLI::App& app, CommandRunners& run);
void AddSynth2dCommand(CLI::App& app, CommandRunners& run);
void AddSynthCommand(CLI::App& app, CommandRunners& run);
void AddRenderCommand(CLI::App& app, CommandRunners& run);
void AddViewCommand(CLI::App& app, CommandRunners& run);
void AddSceneCommand(CLI::App& app, CommandRunners& run);
void AddDemoCommand(CLI::App& app, CommandRunners& run);

/// A word option: the value must be a key of `words`; `message` says which
/// words are allowed (the option's name is put before it).
CLI::Validator OneOf(const std::vector<std::string>& words, const std::string& message);

/// An option taking one of a few words, each standing for a value of an enum:
/// bind the option to the enum and transform with this (other words, and
/// numbers, are refused with the list of words).
template <typename Enum>
CLI::Validator Choice(const std::map<std::string, Enum>& words) {
  std::vector<std::string> names;
  for (const auto& [name, value] : words) names.push_back(name);
  const std::string list = CLI::detail::join(names, ", ");
  return CLI::Validator(
      [words, list](std::string& value) -> std::string {
        const auto it = words.find(value);
        if (it == words.end()) return "give " + list + ", not '" + value + "'";
        value = std::to_string(static_cast<long long>(it->second));
        return "";
      },
      CLI::detail::join(names, "|"));
}

/// The words of the synthetic scenes' shapes and materials (scene, demo).
std::map<std::string, datasets::SceneShape> ShapeWords();
std::map<std::string, datasets::MaterialKind> MaterialWords();
/// The scene photos' sensor options (--shot-noise, --read-noise, --vignetting,
/// --white-balance-spread, --jpeg-quality), for `scene` and `demo`.
void BindSensor(CLI::App* sub, datasets::SensorOptions& s);
/// `--world-unit LENGTH` (synth, demo): its text, read by WorldUnitMm after parsing.
void BindWorldUnit(CLI::App* sub, std::string& text);
/// The length `--world-unit` gave, in millimetres (core/units.h ParseLengthMm); 0 when
/// not given. Throws OptionError naming the option for anything but a length.
double WorldUnitMm(const std::string& text);

}  // namespace texlume::apps
