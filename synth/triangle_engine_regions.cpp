// The distributed run of the per-triangle engine (issue 33, synth/face_regions.h):
// photometry and the band along the region borders placed at rank 0 and sent to the
// others, then each region placed by its rank, growing from the band.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <map>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "core/check.h"
#include "core/errors.h"
#include "core/memory_budget.h"
#include "core/ordered_pipeline.h"
#include "core/timing.h"
#include "synth/face_order.h"
#include "synth/triangle_engine.h"

namespace texlume::synth {

void TriangleEngine::DistributeOver(FaceRegions regions) {
  TEXLUME_CHECK(regions.ranks != nullptr, "a distributed run has ranks");
  TEXLUME_CHECK(regions.partition.num_regions == regions.ranks->Size(), "one region per rank");
  TEXLUME_CHECK(regions.partition.region_of_face.size() == mesh_.faces.size(),
                "the partition is of the engine's mesh");
  regions_ = std::move(regions);
  placed_first_ = BordersPlacedFirst(regions_->partition, face_neighbours_);
}

void TriangleEngine::EstimateOrReceivePhotometry(const ProgressCallback& progress) {
  if (!regions_) return EstimatePhotometry(progress);
  RankCommunicator& ranks = *regions_->ranks;
  ByteWriter out;
  if (ranks.Rank() == 0) {
    EstimatePhotometry(progress);
    out.PutVector(result_.photo_gains);
    out.Put(result_.light_response);
    out.PutVector(result_.white_balance);
    out.PutVector(result_.photo_blur);
  }
  ranks.Broadcast(out.bytes());
  if (ranks.Rank() == 0) return;
  ByteReader in(out.bytes());
  result_.photo_gains = in.GetVector<double>();
  result_.light_response = in.Get<ptm::LightResponse>();
  result_.white_balance = in.GetVector<std::array<double, 3>>();
  result_.photo_blur = in.GetVector<double>();
  TEXLUME_CHECK(result_.photo_gains.size() == photos_.size(), "rank 0 has the same photos");
}

void TriangleEngine::RequireSameInputsAsRankZero(const std::vector<TrianglePatch>& patches) const {
  // FNV-1a over what every rank must agree on: faces (their vertices, hence the
  // face neighbours the band and the regions' order follow), photos, patch
  // rectangles, regions.
  std::uint64_t hash = 0xcbf29ce484222325ull;
  const auto mix = [&hash](std::uint64_t value) { hash = (hash ^ value) * 0x100000001b3ull; };
  mix(mesh_.faces.size());
  for (const std::array<int, 3>& face : mesh_.faces)
    for (const int v : face) mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(v)));
  for (const MeshPhoto& photo : photos_) mix(photo.image_id.value);
  for (std::size_t f = 0; f < patches.size(); ++f) {
    mix(static_cast<std::uint64_t>(patches[f].width));
    mix(static_cast<std::uint64_t>(patches[f].height));
    mix(static_cast<std::uint64_t>(regions_->partition.region_of_face[f]));
  }
  ByteWriter rank_zero;
  rank_zero.Put(hash);
  regions_->ranks->Broadcast(rank_zero.bytes());
  if (ByteReader(rank_zero.bytes()).Get<std::uint64_t>() != hash)
    throw InputError("rank " + std::to_string(regions_->ranks->Rank()),
                     "its mesh, photos, patches or regions differ from rank 0's; give every rank "
                     "the same input files and settings");
}

namespace {

// The name of the machine this rank runs on (ranks on one machine share its memory).
std::string ThisMachine() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "this machine";
  return name;
}

// One rank's patches' estimate and memory limit, as rank 0 gathers them.
struct RankMemory {
  int rank = 0;
  double needed_bytes = 0.0, limit_bytes = 0.0;
  double machine_default_bytes = 0.0;  // DefaultMemoryLimitBytes() of its machine
  bool users_limit = false;            // --memory-limit: the rank's own, not shared
  std::string machine;

  void Write(ByteWriter& out) const {
    out.Put(rank), out.Put(needed_bytes), out.Put(limit_bytes);
    out.Put(machine_default_bytes), out.Put(static_cast<char>(users_limit));
    out.PutString(machine);
  }
  static RankMemory Read(ByteReader& in) {
    RankMemory m;
    m.rank = in.Get<int>(), m.needed_bytes = in.Get<double>(), m.limit_bytes = in.Get<double>();
    m.machine_default_bytes = in.Get<double>(), m.users_limit = in.Get<char>() != 0;
    m.machine = in.GetString();
    TEXLUME_CHECK(in.Remaining() == 0, "a rank's memory message is read whole");
    return m;
  }
};

// What the ranks of one machine may use together under the default limit: their
// shares, at most the machine's default (a launcher that tells no rank how many share
// the machine leaves each the whole default).
double SharedBytes(const std::vector<RankMemory>& on_machine) {
  double shares = 0.0;
  for (const RankMemory& m : on_machine) shares += m.limit_bytes;
  return std::min(shares, on_machine.front().machine_default_bytes);
}

// Empty when every machine's ranks fit; else why not (`what` the patches' description).
std::string MemoryRefusal(const std::map<std::string, std::vector<RankMemory>>& machines,
                          const std::string& what) {
  for (const auto& [name, ranks] : machines) {
    double needed_bytes = 0.0;
    bool users_limit = false;
    for (const RankMemory& m : ranks) {
      needed_bytes += m.needed_bytes;
      users_limit = users_limit || m.users_limit;
    }
    if (users_limit) {  // each rank within its own --memory-limit
      for (const RankMemory& m : ranks)
        if (!(m.needed_bytes <= m.limit_bytes))
          return what + " need about " + MemorySizeText(m.needed_bytes) + " on rank " +
                 std::to_string(m.rank) + " (" + name + "), more than its memory limit of " +
                 MemorySizeText(m.limit_bytes) + " (--memory-limit)";
      continue;
    }
    const double shared_bytes = SharedBytes(ranks);
    if (!(needed_bytes <= shared_bytes))
      return what + " need about " + MemorySizeText(needed_bytes) + " on the " +
             std::to_string(ranks.size()) + " ranks of " + name +
             " together, more than the memory they share, " + MemorySizeText(shared_bytes) +
             " (--memory-limit)";
  }
  return "";
}

// Under the default limit, what rank 0 may use once the other ranks of its machine
// have their estimates: the shared memory less theirs (0 under --memory-limit).
double RankZeroBytes(const std::vector<RankMemory>& on_machine) {
  double others_bytes = 0.0;
  for (const RankMemory& m : on_machine) {
    if (m.users_limit) return 0.0;
    if (m.rank != 0) others_bytes += m.needed_bytes;
  }
  return SharedBytes(on_machine) - others_bytes;
}

}  // namespace

void TriangleEngine::RequirePatchMemoryOnEveryMachine(const PatchGeometry& geometry,
                                                      const std::string& what) {
  RankCommunicator& ranks = *regions_->ranks;
  const mesh::FacePartition& partition = regions_->partition;
  // Rank 0 holds every face (it gathers them and bakes the atlases); another rank
  // its own region's faces and the band rank 0 places first and sends every rank.
  std::vector<char> held(mesh_.faces.size(), 1);
  if (ranks.Rank() != 0)
    for (std::size_t f = 0; f < held.size(); ++f)
      held[f] = partition.region_of_face[f] == ranks.Rank() || placed_first_[f];
  result_.patch_memory_bytes =
      PatchMemoryBytes(geometry, sample_.NumFeatures(), held) + RelitBytesAtMost();
  const RankMemory mine{ranks.Rank(),
                        result_.patch_memory_bytes,
                        static_cast<double>(MemoryLimitBytes()),
                        static_cast<double>(DefaultMemoryLimitBytes()),
                        MemoryLimitIsUsers(),
                        ThisMachine()};
  ByteWriter message;
  mine.Write(message);
  std::map<std::string, std::vector<RankMemory>> machines;
  if (ranks.Rank() == 0) machines[mine.machine].push_back(mine);
  ranks.GatherToRoot(message.bytes(), [&machines](int, std::vector<char>&& from_rank) {
    ByteReader in(from_rank);
    RankMemory m = RankMemory::Read(in);
    machines[m.machine].push_back(std::move(m));
  });
  ByteWriter verdict;
  if (ranks.Rank() == 0) verdict.PutString(MemoryRefusal(machines, what));
  ranks.Broadcast(verdict.bytes());
  ByteReader in(verdict.bytes());
  const std::string refusal = in.GetString();
  TEXLUME_CHECK(in.Remaining() == 0, "rank 0's memory verdict is read whole");
  if (!refusal.empty()) throw InputError("mesh", refusal);
  // Rank 0's later stages (the gather, the atlases, their horizons) may use what the
  // other ranks of its machine do not need.
  if (ranks.Rank() == 0) {
    const double rank_zero_bytes = RankZeroBytes(machines.at(mine.machine));
    if (rank_zero_bytes > static_cast<double>(MemoryLimitBytes()))
      SetSharedMemoryLimitBytes(static_cast<std::uint64_t>(rank_zero_bytes));
  }
}

void TriangleEngine::PlaceRegions(const std::vector<int>& order,
                                  const std::vector<std::array<int, 3>>& neighbours,
                                  const ProgressCallback& progress) {
  const mesh::FacePartition& partition = regions_->partition;
  RankCommunicator& ranks = *regions_->ranks;
  const int rank = ranks.Rank();
  std::vector<char> interior(mesh_.faces.size(), 0);
  for (std::size_t f = 0; f < interior.size(); ++f)
    interior[f] = partition.region_of_face[f] == rank && !placed_first_[f];
  // The borders and the faces next to them first, breadth first along the borders
  // as in one process (BordersPlacedFirst); each region then grows from them, so no
  // two separately placed regions meet.
  const std::vector<int> border_faces =
      mesh::BreadthFirstFaceOrderWithin(order, placed_first_, neighbours);
  PlaceBorders(border_faces, progress);
  const std::vector<int> region_faces = RegionOrder(order, border_faces, interior, neighbours);
  const auto start = std::chrono::steady_clock::now();
  PlaceFaces(region_faces, options_.seed + static_cast<std::uint32_t>(rank), 0, region_faces.size(),
             progress);
  const double placing = SecondsSince(start);
  FinishFaces(std::vector<std::size_t>(region_faces.begin(), region_faces.end()), progress);
  RankRecord record;
  record.rank = rank;
  record.faces = partition.faces_in_region[static_cast<std::size_t>(rank)];
  record.faces_placed = region_faces.size();
  record.seconds_prepare = result_.seconds_prepare;
  record.seconds_region = placing;
  record.seconds_finish = result_.seconds_finish;
  record.patch_memory_bytes = result_.patch_memory_bytes;
  record.peak_resident_bytes = PeakResidentBytes();
  const auto gather = std::chrono::steady_clock::now();
  if (rank != 0) {
    ByteWriter message;
    WriteRegion(region_faces, record, message);
    ranks.GatherToRoot(message.bytes(), {});
    result_.rank_share_only = true;
    return;
  }
  record.bytes_sent = 0;  // rank 0's own faces stay where they are
  result_.rank_records.push_back(record);
  ranks.GatherToRoot({}, [this](int, std::vector<char>&& from_rank) {
    ReadRegion(from_rank);
    std::vector<char>().swap(from_rank);
  });
  result_.seconds_gather = SecondsSince(gather);
  const auto finish = std::chrono::steady_clock::now();
  FinishFaces(std::vector<std::size_t>(border_faces.begin(), border_faces.end()), progress);
  result_.seconds_region_borders += SecondsSince(finish);
  for (std::size_t f = 0; f < done_.size(); ++f)
    TEXLUME_CHECK(done_[f], "every face is placed by a rank or at the borders");
  result_.region_band_faces = border_faces.size();
  result_.region_border_faces = static_cast<std::size_t>(
      std::count(partition.on_border.begin(), partition.on_border.end(), 1));
  result_.region_cut_edges = partition.cut_edges;
  result_.region_of_face = partition.region_of_face;
  CountSources();
}

void TriangleEngine::PlaceBorders(const std::vector<int>& border_faces,
                                  const ProgressCallback& progress) {
  RankCommunicator& ranks = *regions_->ranks;
  const auto start = std::chrono::steady_clock::now();
  ByteWriter out;
  if (ranks.Rank() == 0) {
    if (progress) progress("region borders", 0, border_faces.size());
    PlaceFaces(border_faces, options_.seed + static_cast<std::uint32_t>(ranks.Size()), 0,
               border_faces.size(),
               progress
                   ? ProgressCallback([&](std::string_view, std::size_t done, std::size_t total) {
                       progress("region borders", done, total);
                     })
                   : ProgressCallback());
    WriteFaces(border_faces, out);
  }
  ranks.Broadcast(out.bytes());
  if (ranks.Rank() != 0) {
    ByteReader in(out.bytes());
    ReadFaces(
        in, [this](std::size_t f) { return placed_first_[f] != 0; },
        "rank 0 sends the border faces, once");
    TEXLUME_CHECK(in.Remaining() == 0, "the border faces' message is read whole");
  }
  result_.seconds_region_borders = SecondsSince(start);
}

std::vector<int> TriangleEngine::RegionOrder(
    const std::vector<int>& order, const std::vector<int>& border_faces,
    const std::vector<char>& interior, const std::vector<std::array<int, 3>>& neighbours) const {
  if (!PhotosHeldTogether(photos_)) {
    // The cache-warm photo-by-photo order, kept when the photos do not all fit.
    std::vector<int> region_faces;
    for (const int f : order)
      if (interior[static_cast<std::size_t>(f)]) region_faces.push_back(f);
    return region_faces;
  }
  // Breadth first from every face next to the placed borders at once, those
  // first in the order their border neighbours were placed (the front follows
  // the borders as they were laid).
  std::vector<std::size_t> placed_at(interior.size(),
                                     border_faces.size());  // past: not a border face
  for (std::size_t n = 0; n < border_faces.size(); ++n)
    placed_at[static_cast<std::size_t>(border_faces[n])] = n;
  std::vector<std::pair<std::size_t, int>> next_to_border;
  for (const int f : order) {
    if (!interior[static_cast<std::size_t>(f)]) continue;
    std::size_t first = border_faces.size();
    for (const int g : neighbours[static_cast<std::size_t>(f)])
      if (g >= 0) first = std::min(first, placed_at[static_cast<std::size_t>(g)]);
    if (first < border_faces.size()) next_to_border.emplace_back(first, f);
  }
  std::stable_sort(next_to_border.begin(), next_to_border.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<int> sources;
  for (const auto& [first, f] : next_to_border) sources.push_back(f);
  return mesh::BreadthFirstFaceOrderFrom(sources, order, interior, neighbours);
}

void TriangleEngine::WriteFaces(const std::vector<int>& faces, ByteWriter& out) const {
  out.Put<std::uint64_t>(faces.size());
  for (const int f : faces) {
    const TrianglePatch& p = result_.patches[static_cast<std::size_t>(f)];
    out.Put<std::int32_t>(f);
    out.Put(p.sample_x), out.Put(p.sample_y);
    out.Put(static_cast<std::underlying_type_t<PatchSource>>(p.source)), out.Put(p.views_used);
    out.Put(p.image_score), out.Put(p.prior_shrink), out.Put(p.overlap_error);
    out.Put(p.correction_density.x()), out.Put(p.correction_density.y());
    out.PutMats(p.correction);
    out.PutMats(p.channel_gain);
    out.PutMat(p.detail_source), out.Put<std::int32_t>(p.detail_level);
    if (correction_) correction_->SaveFace(static_cast<std::size_t>(f), out);
  }
}

void TriangleEngine::ReadFaces(ByteReader& in, const std::function<bool(std::size_t)>& expected,
                               const char* what) {
  const auto count = in.Get<std::uint64_t>();
  TEXLUME_CHECK(count <= mesh_.faces.size(), "a rank places faces of the mesh");
  for (std::uint64_t n = 0; n < count; ++n) {
    const auto f = in.Get<std::int32_t>();
    TEXLUME_CHECK(f >= 0 && static_cast<std::size_t>(f) < mesh_.faces.size(), "a face index");
    const auto face = static_cast<std::size_t>(f);
    TEXLUME_CHECK(expected(face) && !done_[face], what);
    TrianglePatch& p = result_.patches[face];
    p.sample_x = in.Get<int>(), p.sample_y = in.Get<int>();
    const auto source = in.Get<std::underlying_type_t<PatchSource>>();
    TEXLUME_CHECK(
        source == static_cast<std::underlying_type_t<PatchSource>>(PatchSource::kPhotos) ||
            source == static_cast<std::underlying_type_t<PatchSource>>(PatchSource::kNeighbours) ||
            source == static_cast<std::underlying_type_t<PatchSource>>(PatchSource::kRandom),
        "a patch's source");
    p.source = static_cast<PatchSource>(source);
    p.views_used = in.Get<int>();
    p.image_score = in.Get<double>(), p.prior_shrink = in.Get<double>();
    p.overlap_error = in.Get<double>();
    p.correction_density.x() = in.Get<double>();
    p.correction_density.y() = in.Get<double>();
    p.correction = in.GetMats();
    p.channel_gain = in.GetMats();
    p.detail_source = in.GetMat();
    p.detail_level = in.Get<std::int32_t>();
    if (correction_) correction_->LoadFace(*this, face, in);
    done_[face] = 1;
  }
}

void TriangleEngine::WriteRegion(const std::vector<int>& faces, const RankRecord& record,
                                 ByteWriter& out) const {
  out.Put(record);
  WriteFaces(faces, out);
  if (correction_) correction_->SaveSums(out);
  // What this message costs, counted in the record at rank 0.
  out.Put<std::uint64_t>(out.bytes().size() + sizeof(std::uint64_t));
}

void TriangleEngine::ReadRegion(const std::vector<char>& message) {
  ByteReader in(message);
  RankRecord record = in.Get<RankRecord>();
  const mesh::FacePartition& partition = regions_->partition;
  ReadFaces(
      in,
      [&](std::size_t f) {
        return partition.region_of_face[f] == record.rank && !placed_first_[f];
      },
      "a rank sends its own region's faces off the border, once");
  if (correction_) correction_->AddSums(in);
  record.bytes_sent = in.Get<std::uint64_t>();
  TEXLUME_CHECK(in.Remaining() == 0, "a rank's message is read whole");
  result_.rank_records.push_back(record);
}

void TriangleEngine::CountSources() {
  result_.num_from_photos = result_.num_from_neighbours = result_.num_random = 0;
  for (const TrianglePatch& p : result_.patches) {
    if (p.source == PatchSource::kPhotos) ++result_.num_from_photos;
    if (p.source == PatchSource::kNeighbours) ++result_.num_from_neighbours;
    if (p.source == PatchSource::kRandom) ++result_.num_random;
  }
}

}  // namespace texlume::synth
