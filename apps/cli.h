#pragma once

#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace texlume::apps {

/// A command line that does not fit the subcommand: exit code 2 and the usage text.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// `--name value` and `--flag` arguments of one subcommand, checked against the
/// names it accepts.
class Arguments {
 public:
  /// @param args  arguments after the subcommand name
  /// @param with_value  option names that take a value
  /// @param flags  option names without a value
  Arguments(const std::vector<std::string>& args, const std::set<std::string>& with_value,
            const std::set<std::string>& flags);

  std::optional<std::string> Get(const std::string& name) const;
  std::string Require(const std::string& name) const;
  bool Has(const std::string& name) const;
  int GetInt(const std::string& name, int fallback) const;
  double GetDouble(const std::string& name, double fallback) const;

 private:
  std::map<std::string, std::string> values_;
};

/// Exit codes of the texlume program.
inline constexpr int kExitOk = 0;
inline constexpr int kExitInputError = 1;     ///< bad or missing input files, problems found
inline constexpr int kExitUsage = 2;          ///< bad command line
inline constexpr int kExitInternalError = 3;  ///< a broken internal invariant (a bug)

/// `texlume inspect`: see docs/cli.md. Returns the exit code.
int RunInspectCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume scene`: writes a synthetic heritage scene. Returns the exit code.
int RunSceneCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume fit`: fits a PTM to an RTI capture. Returns the exit code.
int RunFitCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume btf`: SVD-factorises a BTF capture (paper 004 §III). Returns the exit code.
int RunBtfCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume relight`: renders a PTM under a light. Returns the exit code.
int RunRelightCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume lights-from-sphere`: light directions from a reflective sphere.
int RunLightsFromSphereCommand(const std::vector<std::string>& args, std::ostream& out,
                               std::ostream& err);
/// `texlume synth2d`: image-constrained planar PTM synthesis. Returns the exit code.
int RunSynth2dCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume synth`: the relightable model from photos (paper 003 Algorithm 2).
int RunSynthCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume view MODEL [--port N] [--host H]`: serves the browser viewer of a model
/// folder on localhost until interrupted (docs/viewer.md).
int RunViewCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume render`: a model folder drawn through COLMAP cameras under given lights.
int RunRenderCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `texlume demo`: builds a synthetic scene and inspects it. Returns the exit code.
int RunDemoCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace texlume::apps
