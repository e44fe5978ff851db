// The main job across ranks (issue 33): regions placed by their ranks, borders by
// rank 0, in threads standing in for ranks and through mpirun.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <barrier>
#include <exception>
#include <functional>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/memory_budget.h"
#include "datasets_synthetic/scene.h"
#include "mesh/mesh.h"
#include "pipeline/synth_job.h"
#include "ptm/ptm_io.h"
#include "synth/mesh_synthesis.h"
#include "tests/test_util.h"

namespace texlume::pipeline {
namespace {
namespace fs = std::filesystem;

// Ranks as threads of this process: each call waits for every rank.
class ThreadRanks final : public synth::RankCommunicator {
 public:
  struct Shared {
    explicit Shared(int size) : barrier(size), slots(static_cast<std::size_t>(size)) {}
    std::barrier<> barrier;
    std::vector<std::vector<char>> slots;
  };
  ThreadRanks(Shared& shared, int rank) : shared_(shared), rank_(rank) {}
  int Rank() const override { return rank_; }
  int Size() const override { return static_cast<int>(shared_.slots.size()); }
  void Broadcast(std::vector<char>& bytes) override {
    if (rank_ == 0) shared_.slots[0] = bytes;
    shared_.barrier.arrive_and_wait();
    if (rank_ != 0) bytes = shared_.slots[0];
    shared_.barrier.arrive_and_wait();
  }
  void GatherToRoot(const std::vector<char>& bytes, const Receive& receive) override {
    shared_.slots[static_cast<std::size_t>(rank_)] = bytes;
    shared_.barrier.arrive_and_wait();
    if (rank_ == 0)
      for (int r = 1; r < Size(); ++r)
        receive(r, std::move(shared_.slots[static_cast<std::size_t>(r)]));
    shared_.barrier.arrive_and_wait();
  }

 private:
  Shared& shared_;
  int rank_;
};

class DistributedSynthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new testing::TempDir;
    datasets::SceneOptions o = datasets::SmallObjectSceneOptions(datasets::SceneShape::kSphere,
                                                                 datasets::MaterialKind::kStone);
    o.num_held_out_views = 1;
    o.write_btf = false;
    datasets::GenerateScene(o, tmp_->path() / "scene");
    ptm::WritePtmExr(datasets::FitSceneSample(tmp_->path() / "scene"), tmp_->path() / "sample.exr");
    SynthJobOptions one = Job("one");
    one.compare_regions = {2, 3};  // the regions of ThreeRanks... among them
    one_ = new SynthJobSummary(RunSynthJob(one));
  }
  static void TearDownTestSuite() {
    delete one_;
    delete tmp_;
  }
  static SynthJobOptions Job(const std::string& out) {
    SynthJobOptions j;
    const fs::path object = tmp_->path() / "scene/object";
    j.model_dir = object / "sparse";
    j.images_dir = object / "images";
    j.lights_file = object / "lights.json";
    j.mesh_file = object / "mesh.ply";
    j.sample_file = tmp_->path() / "sample.exr";
    j.out_dir = tmp_->path() / out;
    j.synthesis.sample_texel_size = 0.004;
    j.atlas.atlas_size = 512;
    j.write_report = false;
    return j;
  }
  static std::string SynthCommand(const std::string& out) {
    const fs::path object = tmp_->path() / "scene/object";
    return std::string(TEXLUME_BINARY) + " synth --model " + (object / "sparse").string() +
           " --images " + (object / "images").string() + " --lights " +
           (object / "lights.json").string() + " --mesh " + (object / "mesh.ply").string() +
           " --sample " + (tmp_->path() / "sample.exr").string() +
           " --sample-texel-size 0.004 --atlas-size 512 --no-report --out " +
           (tmp_->path() / out).string();
  }
  static std::string Mpirun(int ranks) {
    // As root (CI), OpenMPI asks to be told; one thread per rank on a small machine.
    return "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1 "
           "timeout 600 " TEXLUME_MPIEXEC " --oversubscribe -np " +
           std::to_string(ranks) + " ";
  }
  static nlohmann::json Manifest(const std::string& out) {
    return nlohmann::json::parse(testing::ReadText(tmp_->path() / out / "manifest.json"));
  }
  static testing::TempDir* tmp_;
  static SynthJobSummary* one_;
};
testing::TempDir* DistributedSynthTest::tmp_ = nullptr;
SynthJobSummary* DistributedSynthTest::one_ = nullptr;

// The job on `size` ranks in threads (`own` changes a rank's options); rank 0's
// summary, or the first error.
SynthJobSummary RunOnThreadRanks(const SynthJobOptions& job, int size,
                                 const std::function<void(int, SynthJobOptions&)>& own_options = {},
                                 std::vector<std::string>* messages = nullptr) {
  ThreadRanks::Shared shared(size);
  std::vector<ThreadRanks> ranks;
  for (int r = 0; r < size; ++r) ranks.emplace_back(shared, r);
  std::vector<SynthJobSummary> summaries(static_cast<std::size_t>(size));
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(size));
  std::vector<std::thread> threads;
  for (int r = 0; r < size; ++r)
    threads.emplace_back([&, r] {
      try {
        SynthJobOptions own = job;
        own.ranks = &ranks[static_cast<std::size_t>(r)];
        if (own_options) own_options(r, own);
        summaries[static_cast<std::size_t>(r)] = RunSynthJob(own);
      } catch (...) {
        errors[static_cast<std::size_t>(r)] = std::current_exception();
        shared.barrier.arrive_and_drop();  // the other ranks go on (and fail) without it
      }
    });
  for (std::thread& t : threads) t.join();
  if (messages)
    for (const std::exception_ptr& e : errors) try {
        if (e) std::rethrow_exception(e);
        messages->push_back("");
      } catch (const std::exception& error) {
        messages->push_back(error.what());
      }
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  for (int r = 1; r < size; ++r)
    EXPECT_TRUE(summaries[static_cast<std::size_t>(r)].rank_share_only);
  return summaries[0];
}

TEST_F(DistributedSynthTest, ThreeRanksPlaceEveryFaceAndRankZeroWritesTheModel) {
  const SynthJobSummary three = RunOnThreadRanks(Job("threads3"), 3);
  EXPECT_FALSE(three.rank_share_only);
  EXPECT_EQ(three.faces, one_->faces);
  // Whether a face is placed from the photos does not depend on the order.
  EXPECT_EQ(three.from_photos, one_->from_photos);
  EXPECT_EQ(three.from_photos + three.from_neighbours + three.random, three.faces);
  const nlohmann::json d = Manifest("threads3")["distributed"];
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["ranks"], 3);
  std::size_t placed = d["region_band_faces"];
  EXPECT_GT(placed, d["region_border_faces"].get<std::size_t>());  // the borders and beyond
  for (const auto& rank : d["per_rank"]) {
    placed += rank["faces_placed"].get<std::size_t>();
    EXPECT_GT(rank["faces_placed"].get<std::size_t>(), three.faces / 6);  // regions balanced
    if (rank["rank"] != 0) {
      EXPECT_GT(rank["bytes_sent"].get<std::size_t>(), 0u);
    }
  }
  EXPECT_EQ(placed, three.faces);  // every face placed once, by one rank
  EXPECT_FALSE(Manifest("threads3").contains("region_comparison"));  // not asked for
  // The borders and the faces next to them placed first, each region grown from them: the borders
  // and the edges next to them agree no worse than other edges do (with a margin for a few dozen
  // border edges).
  const nlohmann::json& e = d["edge_mismatch"];
  EXPECT_GT(e["region_borders"]["edges"].get<int>(), 10);
  EXPECT_LT(e["region_borders"]["mean"].get<double>(), 1.5 * e["elsewhere"]["mean"].get<double>());
  EXPECT_LT(e["next_to_borders"]["mean"].get<double>(), 1.5 * e["elsewhere"]["mean"].get<double>());
  // Where each region's own faces meet the band rank 0 placed.
  EXPECT_GT(e["next_to_band"]["edges"].get<int>(), e["region_borders"]["edges"].get<int>());
  EXPECT_LT(e["next_to_band"]["mean"].get<double>(), 1.5 * e["elsewhere"]["mean"].get<double>());
  EXPECT_GT(e["region_borders"]["standard_error"].get<double>(), 0.0);
  EXPECT_GT(e["next_to_borders"]["edges"].get<int>(), e["region_borders"]["edges"].get<int>());
  EXPECT_LT(e["next_to_borders"]["edges"].get<int>(), e["elsewhere"]["edges"].get<int>());
  const nlohmann::json one = Manifest("one");
  EXPECT_FALSE(one.contains("distributed"));  // one process: as before
  // ...but it measures the same edge classes on the same three regions.
  ASSERT_EQ(one["region_comparison"].size(), 2u);
  EXPECT_EQ(one["settings"]["compare_regions"], nlohmann::json({2, 3}));
  const nlohmann::json& c = one["region_comparison"][1];
  EXPECT_EQ(c["regions"], 3);
  EXPECT_EQ(c["region_cut_edges"], d["region_cut_edges"]);
  // Two regions have fewer edges between them than three.
  EXPECT_LT(one["region_comparison"][0]["edge_mismatch"]["region_borders"]["edges"].get<int>(),
            c["edge_mismatch"]["region_borders"]["edges"].get<int>());
  for (const char* edges : {"region_borders", "next_to_borders", "next_to_band", "elsewhere"}) {
    EXPECT_EQ(c["edge_mismatch"][edges]["edges"], e[edges]["edges"]) << edges;
    EXPECT_GT(c["edge_mismatch"][edges]["mean"].get<double>(), 0.0) << edges;
  }
}

TEST_F(DistributedSynthTest, ARankWithOtherInputsStopsWithAnErrorNamingIt) {
  std::vector<std::string> messages;
  const auto other_texel_size = [](int rank, SynthJobOptions& own) {
    if (rank == 1) own.synthesis.sample_texel_size = 0.005;  // other patch rectangles
  };
  EXPECT_ANY_THROW(RunOnThreadRanks(Job("differ"), 2, other_texel_size, &messages));
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_NE(messages[1].find("rank 1"), std::string::npos) << messages[1];
  EXPECT_NE(messages[1].find("differ from rank 0's"), std::string::npos) << messages[1];
  EXPECT_FALSE(fs::exists(tmp_->path() / "differ" / "manifest.json"));
}

// The default memory limit again however a block ends.
struct DefaultMemoryLimitAtEnd {
  ~DefaultMemoryLimitAtEnd() { SetMemoryLimitBytes(0); }
};

TEST_F(DistributedSynthTest, RanksOnOneMachineShareItsMemoryRankZeroHoldingEveryFace) {
  const DefaultMemoryLimitAtEnd restore;
  const double one_process =
      Manifest("one")["resources"]["patch_memory_estimate_bytes"].get<double>();
  ASSERT_GT(one_process, 0.0);
  // Two ranks whose shares of the machine are each below one process's need run
  // together (an equal split would refuse rank 0)...
  SetSharedMemoryLimitBytes(static_cast<std::uint64_t>(0.9 * one_process));
  EXPECT_NO_THROW(RunOnThreadRanks(Job("share2"), 2));
  // ...since rank 0 gathers and bakes every face, as one process, and the other
  // holds its region and the borders; rank 0 then takes what rank 1 does not need.
  const nlohmann::json per_rank = Manifest("share2")["distributed"]["per_rank"];
  ASSERT_EQ(per_rank.size(), 2u);
  const double rank_zero = per_rank[0]["patch_memory_bytes"].get<double>();
  const double rank_one = per_rank[1]["patch_memory_bytes"].get<double>();
  EXPECT_DOUBLE_EQ(rank_zero, one_process);
  EXPECT_GT(rank_one, 0.2 * one_process);
  EXPECT_LT(rank_one, 0.8 * one_process);
  // (Within the bytes the shares are truncated to, once when set and once when split.)
  EXPECT_NEAR(static_cast<double>(MemoryLimitBytes()), 1.8 * one_process - rank_one, 4.0);
  EXPECT_FALSE(MemoryLimitIsUsers());
  // A little less than their need together refuses on every rank, with the same message.
  SetSharedMemoryLimitBytes(static_cast<std::uint64_t>(0.49 * (rank_zero + rank_one)));
  std::vector<std::string> messages;
  EXPECT_ANY_THROW(RunOnThreadRanks(Job("share2_refused"), 2, {}, &messages));
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_EQ(messages[0], messages[1]);
  EXPECT_NE(messages[0].find("on the 2 ranks of"), std::string::npos) << messages[0];
  EXPECT_FALSE(fs::exists(tmp_->path() / "share2_refused" / "manifest.json"));
  // The user's --memory-limit stays each rank's own: rank 0 is refused at 0.9 of its need.
  SetMemoryLimitBytes(static_cast<std::uint64_t>(0.9 * one_process));
  messages.clear();
  EXPECT_ANY_THROW(RunOnThreadRanks(Job("share2_users"), 2, {}, &messages));
  ASSERT_EQ(messages.size(), 2u);
  EXPECT_EQ(messages[0], messages[1]);
  EXPECT_NE(messages[0].find("on rank 0"), std::string::npos) << messages[0];
  EXPECT_NE(messages[0].find("--memory-limit"), std::string::npos) << messages[0];
  EXPECT_FALSE(fs::exists(tmp_->path() / "share2_users" / "manifest.json"));
}

TEST_F(DistributedSynthTest, MpirunWithTwoAndThreeRanksTakesTheSameCommandLine) {
  std::string output;
  for (const int ranks : {2, 3}) {
    const std::string out = "mpi" + std::to_string(ranks);
    ASSERT_EQ(testing::RunCommand(Mpirun(ranks) + SynthCommand(out), &output), 0) << output;
    // One summary line, from rank 0.
    std::size_t lines = 0;
    for (std::size_t at = output.find("Synthesised"); at != std::string::npos;
         at = output.find("Synthesised", at + 1))
      ++lines;
    EXPECT_EQ(lines, 1u) << output;
    const nlohmann::json m = Manifest(out);
    EXPECT_EQ(m["distributed"]["ranks"], ranks);
    EXPECT_EQ(m["summary"]["from_photos"].get<std::size_t>(), one_->from_photos);
    EXPECT_TRUE(fs::exists(tmp_->path() / out / "ptm_atlas_0.exr"));
  }
}

TEST_F(DistributedSynthTest, MpirunRefusesOtherCommandsAndEndsEveryRankOnBadInput) {
  std::string output;
  EXPECT_EQ(testing::RunCommand(Mpirun(2) + TEXLUME_BINARY " inspect --model " +
                                    (tmp_->path() / "scene/object/sparse").string(),
                                &output),
            2)
      << output;
  EXPECT_NE(output.find("only texlume synth runs across MPI ranks"), std::string::npos) << output;
  std::string command = SynthCommand("bad");
  command.replace(command.find("mesh.ply"), 8, "missing.ply");
  EXPECT_EQ(testing::RunCommand(Mpirun(2) + command, &output), 1) << output;
  EXPECT_NE(output.find("missing.ply"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(tmp_->path() / "bad" / "manifest.json"));
  command = SynthCommand("graphcut") + " --engine graphcut";
  EXPECT_EQ(testing::RunCommand(Mpirun(2) + command, &output), 2) << output;
}

}  // namespace
}  // namespace texlume::pipeline
