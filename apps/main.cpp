// texlume: one program, one subcommand per pipeline step. Each subcommand is a
// thin wrapper over a tested Run...Command function (apps/cli.h).
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli.h"
#include "core/check.h"
#include "core/errors.h"

namespace {

constexpr const char* kUsage =
    "texlume: relightable PTM models from photos and a material sample\n"
    "\n"
    "Usage: texlume <command> [options]\n"
    "\n"
    "Commands:\n"
    "  inspect --model DIR [--mesh FILE] [--images DIR] [--lights FILE] [--json FILE]\n"
    "          [--max-buffer-size N]\n"
    "      Summarise a COLMAP model (.bin or .txt), check a mesh, lights and image\n"
    "      files, and report which triangles the photos see fully.\n"
    "  fit --images DIR --lights FILE.lp --out sample.ptm [--format lrgb|rgb] [--robust]\n"
    "      [--exr FILE] [--web DIR] [--band-rows N]\n"
    "      Fit a PTM to an RTI capture (writes sample.ptm.json with settings and timings).\n"
    "  btf --capture DIR --out DIR [--components N]\n"
    "      SVD-factorise a BTF capture (btf.json + one image per view and light) into N\n"
    "      geometry maps and appearance functions (default 40); prints the error table.\n"
    "  relight --ptm FILE(.ptm|.exr) --light lx,ly,lz --out image.png [--normals FILE]\n"
    "      [--gain G] [--specular KS]\n"
    "      Render a PTM under a light (texture frame: x right, y up, z out).\n"
    "  lights-from-sphere --images DIR --out lights.lp [--circle cx,cy,r] [--threshold F]\n"
    "      Light directions from the highlight on a glossy sphere in every photo.\n"
    "  synth2d --sample FILE.ptm --photos DIR --lights FILE.lp --out DIR [--scale R]\n"
    "          [--width W --height H] [--block N] [--overlap N] [--top-k K] [--seam]\n"
    "          [--unconstrained] [--seed S]\n"
    "      Image-constrained planar PTM synthesis (paper 003 Algorithm 1).\n"
    "  synth --model DIR --images DIR --lights FILE.json --mesh FILE --sample FILE.ptm\n"
    "        --sample-texel-size T --out DIR [--atlas charts|per-triangle] [--atlas-size N]\n"
    "        [--strip N] [--top-k K] [--best-view-only] [--max-views N]\n"
    "        [--tangent-frame auto|photos|first-edge | --tangent-field x,y,z]\n"
    "        [--gutter N] [--max-subdivisions N] [--seed S] [--no-report]\n"
    "      The relightable model: per-triangle image-constrained PTM synthesis on the mesh\n"
    "      (paper 003 Algorithm 2), blended, packed into atlases, exported, with report.html\n"
    "      (docs/synth.md).\n"
    "  render --model DIR --cameras COLMAP_DIR --lights FILE.json --out DIR\n"
    "         [--baseline flat|baked] [--samples N] [--truth DIR [--truth-masks DIR]]\n"
    "         [--reduced-factor R]\n"
    "      Render a model folder for every image of a COLMAP model under its light(s).\n"
    "  view MODEL_DIR [--port N] [--host ADDRESS]\n"
    "      Serve the model's relighting preview in the browser (http://127.0.0.1:8080/;\n"
    "      --port 0 picks a free port).\n"
    "  scene --out DIR [--kind sphere|cylinder|plane|torus] [--material stone|brick|grooves]\n"
    "        [--seed S] [--images N] [--camera-model pinhole|opencv] [--width W] [--height H]\n"
    "        [--capture-size N] [--capture-lights N] [--held-out-lights N] [--held-out-views N]\n"
    "        [--held-out-scale N] [--texel-size T] [--relief R] [--specular KS] [--samples N] "
    "[--no-btf]\n"
    "        [--fixed-exposure] [--mesh-resolution N]\n"
    "      Write a synthetic heritage scene with ground truth (docs/synthetic_scenes.md).\n"
    "  demo [--out DIR] [--kind SHAPE] [--material MATERIAL] [--seed S]\n"
    "      The whole job on a synthetic scene: scene, inspect, fit, synth, render held-out\n"
    "      views and the two baselines; writes DIR/report.html (DIR: out).\n"
    "  help, --help\n"
    "  version, --version\n"
    "\n"
    "Exit codes: 0 success, 1 bad input (the message names the file), 2 bad command line,\n"
    "3 internal error (a bug in texlume).\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace texlume::apps;
  if (argc < 2) {
    std::cerr << kUsage;
    return kExitUsage;
  }
  const std::string command = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  try {
    if (command == "help" || command == "--help" || command == "-h") {
      std::cout << kUsage;
      return kExitOk;
    }
    if (command == "version" || command == "--version") {
      std::cout << "texlume 0.1.0\n";
      return kExitOk;
    }
    if (command == "inspect") return RunInspectCommand(args, std::cout, std::cerr);
    if (command == "fit") return RunFitCommand(args, std::cout, std::cerr);
    if (command == "btf") return RunBtfCommand(args, std::cout, std::cerr);
    if (command == "relight") return RunRelightCommand(args, std::cout, std::cerr);
    if (command == "lights-from-sphere")
      return RunLightsFromSphereCommand(args, std::cout, std::cerr);
    if (command == "synth2d") return RunSynth2dCommand(args, std::cout, std::cerr);
    if (command == "synth") return RunSynthCommand(args, std::cout, std::cerr);
    if (command == "render") return RunRenderCommand(args, std::cout, std::cerr);
    if (command == "view") return RunViewCommand(args, std::cout, std::cerr);
    if (command == "scene") return RunSceneCommand(args, std::cout, std::cerr);
    if (command == "demo") return RunDemoCommand(args, std::cout, std::cerr);
    throw UsageError("unknown command '" + command + "'");
  } catch (const UsageError& e) {
    std::cerr << "texlume " << command << ": " << e.what() << "\n\n" << kUsage;
    return kExitUsage;
  } catch (const texlume::OptionError& e) {
    std::cerr << "texlume " << command << ": invalid option: " << e.what() << "\n";
    return kExitUsage;
  } catch (const texlume::InternalError& e) {
    std::cerr << "internal error (a bug in texlume; please report it with the command line): "
              << e.what() << "\n";
    return kExitInternalError;
  } catch (const texlume::InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitInputError;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitInputError;
  }
}
