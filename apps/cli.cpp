#include "apps/cli.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/check.h"
#include "core/errors.h"
#include "core/memory_budget.h"
#include "core/provenance.h"

namespace texlume::apps {
namespace {

// The edit distance between two option names (Levenshtein), for "did you mean".
std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t next =
          std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0u : 1u)});
      diagonal = row[j];
      row[j] = next;
    }
  }
  return row[b.size()];
}

// The closest of `names` to `word`, when close enough to be a typo.
std::string Nearest(const std::string& word, const std::vector<std::string>& names) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const std::string& name : names) {
    const std::size_t d = EditDistance(word, name);
    if (d < best_distance) best = name, best_distance = d;
  }
  return best;
}

// Words left over after parsing: an unknown command or option, with the
// nearest name; empty when nothing is left over.
std::string ExtrasMessage(CLI::App& app, const CLI::App* sub) {
  if (!sub) {
    if (app.remaining().empty()) return "";
    std::vector<std::string> names;
    for (const CLI::App* s : app.get_subcommands({})) names.push_back(s->get_name());
    const std::string word = app.remaining().front();
    const std::string near = Nearest(word, names);
    return "unknown command '" + word + "'" +
           (near.empty() ? "" : "; did you mean '" + near + "'?");
  }
  if (sub->remaining().empty()) return "";
  std::vector<std::string> names;
  for (const CLI::Option* o : sub->get_options())
    for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
  const std::string word = sub->remaining().front();
  const std::string near = Nearest(word.substr(0, word.find('=')), names);
  return (word.rfind("-", 0) == 0 ? "unknown option " : "unexpected argument ") + word +
         (near.empty() ? "" : "; did you mean " + near + "?");
}

std::string CommandName(const CLI::App* sub) {
  return sub ? "texlume " + sub->get_name() : std::string("texlume");
}

std::string HelpHint(const CLI::App* sub) {
  return "Run '" + CommandName(sub) + " --help' for " + (sub ? "its options" : "the commands") +
         ".\n";
}

}  // namespace

namespace {
synth::RankCommunicator* g_ranks = nullptr;

// Only `texlume synth` runs across ranks, and only in a build with MPI.
void RefuseSeveralRanksUnlessSynth(const CLI::App& sub) {
  if (!LaunchedAsSeveralRanks()) return;
  if (!g_ranks)
    throw UsageError(
        "started as one of several MPI ranks, but this texlume was built without MPI "
        "(scripts/install_deps.sh installs OpenMPI; then rebuild)");
  if (sub.get_name() != "synth")
    throw UsageError("only texlume synth runs across MPI ranks; run texlume " + sub.get_name() +
                     " in one process (without mpirun)");
}
}  // namespace

namespace {
int EnvironmentNumber(const char* name) {
  const char* value = std::getenv(name);
  return value ? std::atoi(value) : 0;
}
}  // namespace

bool LaunchedAsSeveralRanks() {
  // OpenMPI's mpirun, MPICH's Hydra (PMI), Slurm's srun (a PMI/PMIx rank in a step of tasks).
  if (EnvironmentNumber("OMPI_COMM_WORLD_SIZE") > 1 || EnvironmentNumber("PMI_SIZE") > 1)
    return true;
  return (std::getenv("PMIX_RANK") || std::getenv("PMI_RANK")) &&
         EnvironmentNumber("SLURM_STEP_NUM_TASKS") > 1;
}

int RanksOnThisMachine() {
  for (const char* name : {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"})
    if (EnvironmentNumber(name) > 0) return EnvironmentNumber(name);
  return 1;
}

void SetRanks(synth::RankCommunicator* ranks) { g_ranks = ranks; }
synth::RankCommunicator* Ranks() { return g_ranks; }

int RunTexlume(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  RecordCommandLine(argc, argv);
  CLI::App app("texlume: relightable PTM models from photos and a material sample", "texlume");
  app.footer(
      "Exit codes: 0 success, 1 bad input (the message names the file), 2 bad command line, "
      "3 internal error (a bug in texlume). docs/cli.md has the details.");
  app.set_version_flag("--version", std::string("texlume ") + TexlumeVersion());
  app.allow_extras();
  // An option given twice takes its last value, as the command line always has.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  CommandRunners run;
  for (const auto add : {AddInspectCommand, AddFitCommand, AddBtfCommand, AddRelightCommand,
                         AddLightsFromSphereCommand, AddSynth2dCommand, AddSynthCommand,
                         AddRenderCommand, AddViewCommand, AddSceneCommand, AddDemoCommand})
    add(app, run);
  app.add_subcommand("help", "Print this help.");
  app.add_subcommand("version", "Print the version.");
  // --memory-limit before or after the command's name (docs/cli.md).
  std::string memory_limit;
  const char* memory_help =
      "the memory a run may use (bytes, or 512M, 8G; default: 3/4 of the machine's); larger "
      "inputs are refused up front";
  app.add_option("--memory-limit", memory_limit, memory_help);
  for (CLI::App* sub : app.get_subcommands({})) {
    sub->allow_extras();
    if (sub->get_name() != "help" && sub->get_name() != "version")
      sub->add_option("--memory-limit", memory_limit, memory_help);
  }
  const CLI::App* sub = nullptr;
  try {
    app.parse(argc, argv);
    const std::vector<CLI::App*> used = app.get_subcommands();
    sub = used.empty() ? nullptr : used.front();
    if (sub && sub->get_name() == "help")
      return (out << app.get_formatter()->make_help(&app, "texlume", CLI::AppFormatMode::Normal),
              kExitOk);
    if (sub && sub->get_name() == "version")
      return (out << "texlume " << TexlumeVersion() << "\n", kExitOk);
    if (const std::string extras = ExtrasMessage(app, sub); !extras.empty())
      throw UsageError(extras);
    if (!sub) throw UsageError("give a command");
    SetMemoryLimitBytes(memory_limit.empty() ? 0 : ParseMemorySize(memory_limit));
    // Ranks on one machine share its memory: each takes its share of the default.
    if (memory_limit.empty() && LaunchedAsSeveralRanks() && RanksOnThisMachine() > 1)
      SetSharedMemoryLimitBytes(MemoryLimitBytes() /
                                static_cast<std::uint64_t>(RanksOnThisMachine()));
    RefuseSeveralRanksUnlessSynth(*sub);
    return run.at(sub)(out, err);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e, out, err);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e, out, err);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e, out, err);
  } catch (const CLI::ParseError& e) {
    // An unknown option explains a missing required one (a typo): say so first.
    for (const CLI::App* s : app.get_subcommands()) sub = s;
    const std::string extras = ExtrasMessage(app, sub);
    err << CommandName(sub) << ": " << (extras.empty() ? e.what() : extras) << "\n"
        << HelpHint(sub);
    return kExitUsage;
  } catch (const UsageError& e) {
    err << CommandName(sub) << ": " << e.what() << "\n" << HelpHint(sub);
    return kExitUsage;
  } catch (const OptionError& e) {
    err << CommandName(sub) << ": invalid option: " << e.what() << "\n" << HelpHint(sub);
    return kExitUsage;
  } catch (const InternalError& e) {
    err << "internal error (a bug in texlume; please report it with the command line): " << e.what()
        << "\n";
    return kExitInternalError;
  } catch (const std::exception& e) {
    err << "error: " << e.what() << "\n";
    return kExitInputError;
  }
}

}  // namespace texlume::apps
