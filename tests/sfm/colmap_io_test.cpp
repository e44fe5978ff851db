#include "sfm/colmap_io.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/file_util.h"
#include "tests/sfm/reconstruction_matchers.h"
#include "tests/test_util.h"

namespace texlume::sfm {
namespace {

using testing::TempDir;
using testing::WriteText;

TEST(ColmapIo, TextRoundTripThroughStringStreamsIsExact) {
  const Reconstruction r = MakeTestReconstruction();
  std::stringstream cameras, images, points;
  WriteCamerasText(r, cameras);
  WriteImagesText(r, images);
  WritePoints3DText(r, points);
  Reconstruction back;
  back.cameras = ReadCamerasText(cameras, "cameras.txt");
  back.images = ReadImagesText(images, "images.txt");
  back.points3d = ReadPoints3DText(points, "points3D.txt");
  ExpectSameReconstruction(r, back, 0.0);
}

TEST(ColmapIo, BinaryRoundTripThroughStringStreamsIsExact) {
  const Reconstruction r = MakeTestReconstruction();
  std::stringstream cameras, images, points;
  WriteCamerasBinary(r, cameras);
  WriteImagesBinary(r, images);
  WritePoints3DBinary(r, points);
  Reconstruction back;
  back.cameras = ReadCamerasBinary(cameras, "cameras.bin");
  back.images = ReadImagesBinary(images, "images.bin");
  back.points3d = ReadPoints3DBinary(points, "points3D.bin");
  ExpectSameReconstruction(r, back, 0.0);
}

TEST(ColmapIo, FolderRoundTripDetectsFormatAndIgnoresRigsAndFrames) {
  TempDir tmp;
  const Reconstruction r = MakeTestReconstruction();
  WriteModel(r, tmp / "bin", ModelFormat::kBinary);
  WriteModel(r, tmp / "txt", ModelFormat::kText);
  WriteText(tmp / "txt" / "rigs.txt", "# Rig list\n1 1\n");
  WriteText(tmp / "txt" / "frames.txt", "# Frame list\n");
  const LoadedModel from_bin = ReadModel(tmp / "bin");
  const LoadedModel from_txt = ReadModel(tmp / "txt");
  EXPECT_EQ(from_bin.format, ModelFormat::kBinary);
  EXPECT_EQ(from_txt.format, ModelFormat::kText);
  EXPECT_EQ(from_txt.ignored_files.size(), 2u);
  ExpectSameReconstruction(r, from_bin.reconstruction);
  ExpectSameReconstruction(r, from_txt.reconstruction);
  // No temporary files are left behind.
  for (const auto& entry : std::filesystem::directory_iterator(tmp / "bin")) {
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos);
  }
}

TEST(ColmapIo, ImagesWithoutPointsKeepTheirEmptyLine) {
  const std::string text =
      "# comment\n"
      "1 1 0 0 0 0 0 0 1 a.png\n"
      "\n"
      "2 1 0 0 0 1 2 3 1 b with space.png\n"
      "10.5 20.25 -1 3 4 -1\n";
  std::istringstream in(text);
  const auto images = ReadImagesText(in, "images.txt");
  ASSERT_EQ(images.size(), 2u);
  EXPECT_TRUE(images.at(ImageId(1)).points2d.empty());
  EXPECT_EQ(images.at(ImageId(2)).name, "b with space.png");
  ASSERT_EQ(images.at(ImageId(2)).points2d.size(), 2u);
  EXPECT_FALSE(images.at(ImageId(2)).points2d[0].point3d_id.IsValid());
  EXPECT_TRUE(images.at(ImageId(2)).ProjectionCenter().isApprox(Eigen::Vector3d(-1, -2, -3)));
}

TEST(ColmapIo, NonUnitQuaternionIsNormalisedLikeColmap) {
  std::istringstream in("1 2 0 0 0 0 0 0 1 a.png\n\n");
  const auto images = ReadImagesText(in, "images.txt");
  EXPECT_NEAR(images.at(ImageId(1)).cam_from_world.rotation.norm(), 1.0, 1e-15);
}

// ----------------------------------------------------------------- bad input

TEST(ColmapIoBadInput, EveryTruncationOfEveryBinaryFileIsACleanError) {
  Reconstruction r = MakeTestReconstruction();
  // Keep the files small so every prefix can be tried.
  while (r.points3d.size() > 5) r.points3d.erase(std::prev(r.points3d.end()));
  for (auto& [id, image] : r.images) {
    image.points2d.resize(std::min<std::size_t>(image.points2d.size(), 3));
    for (auto& p : image.points2d) p.point3d_id = Point3DId();
  }
  for (auto& [id, p] : r.points3d) p.track.clear();
  std::stringstream cameras, images, points;
  WriteCamerasBinary(r, cameras);
  WriteImagesBinary(r, images);
  WritePoints3DBinary(r, points);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"cameras.bin", cameras.str()}, {"images.bin", images.str()}, {"points3D.bin", points.str()}};
  for (const auto& file : files) {
    const std::string& name = file.first;  // a plain name: lambdas capture it (clang 14)
    const std::string& bytes = file.second;
    for (std::size_t len = 0; len < bytes.size(); ++len) {
      std::istringstream in(bytes.substr(0, len));
      const std::string error = testing::InputErrorMessage([&] {
        if (name == "cameras.bin") ReadCamerasBinary(in, name);
        if (name == "images.bin") ReadImagesBinary(in, name);
        if (name == "points3D.bin") ReadPoints3DBinary(in, name);
      });
      ASSERT_FALSE(error.empty()) << name << " truncated to " << len << " bytes was accepted";
      ASSERT_EQ(error.rfind(name + ":", 0), 0u) << error;
    }
  }
}

TEST(ColmapIoBadInput, HugeCountsAreRefusedBeforeAllocating) {
  std::stringstream s;
  WriteU64(s, 1ull << 60);  // cameras claimed
  WriteU32(s, 1);
  std::string error = testing::InputErrorMessage([&] { ReadCamerasBinary(s, "cameras.bin"); });
  EXPECT_NE(error.find("count"), std::string::npos) << error;

  // An image whose 2D point count is far larger than the bytes left.
  std::stringstream img;
  WriteU64(img, 1);
  WriteU32(img, 1);
  for (double v : {1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}) WriteF64(img, v);
  WriteU32(img, 1);
  img.write("a.png", 6);
  WriteU64(img, 0xFFFFFFFFFFFFull);
  error = testing::InputErrorMessage([&] { ReadImagesBinary(img, "images.bin"); });
  EXPECT_NE(error.find("2D point (image 1) count"), std::string::npos) << error;

  // A point whose track length is too large.
  std::stringstream pts;
  WriteU64(pts, 1);
  WriteU64(pts, 7);
  for (int i = 0; i < 3; ++i) WriteF64(pts, 0.0);
  for (int i = 0; i < 3; ++i) WriteU8(pts, 0);
  WriteF64(pts, 0.5);
  WriteU64(pts, 1ull << 40);
  error = testing::InputErrorMessage([&] { ReadPoints3DBinary(pts, "points3D.bin"); });
  EXPECT_NE(error.find("track element (point 7) count"), std::string::npos) << error;
}

TEST(ColmapIoBadInput, UnknownModelIdIsNamed) {
  std::stringstream s;
  WriteU64(s, 1);
  WriteU32(s, 1);
  WriteI32(s, 11);
  WriteU64(s, 640);
  WriteU64(s, 480);
  for (int i = 0; i < 4; ++i) WriteF64(s, 1.0);
  const std::string error =
      testing::InputErrorMessage([&] { ReadCamerasBinary(s, "cameras.bin"); });
  EXPECT_NE(error.find("unknown camera model id 11"), std::string::npos) << error;
}

TEST(ColmapIoBadInput, MissingNulInImageNameIsNamed) {
  std::stringstream img;
  WriteU64(img, 1);
  WriteU32(img, 1);
  for (double v : {1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0}) WriteF64(img, v);
  WriteU32(img, 1);
  img.write("name_without_nul_and_more_bytes_after_it", 40);
  const std::string error =
      testing::InputErrorMessage([&] { ReadImagesBinary(img, "images.bin"); });
  EXPECT_NE(error.find("no terminating NUL"), std::string::npos) << error;
}

TEST(ColmapIoBadInput, TrailingBytesAreRefused) {
  const Reconstruction r = MakeTestReconstruction();
  std::stringstream s;
  WriteCamerasBinary(r, s);
  s << "xx";
  EXPECT_NE(testing::InputErrorMessage([&] {
              ReadCamerasBinary(s, "cameras.bin");
            }).find("unexpected bytes"),
            std::string::npos);
}

struct BadTextCase {
  std::string file;
  std::string text;
  std::string expected;  // substring of the message, which must start "file:line:"
  int line;
};

TEST(ColmapIoBadInput, MalformedTextLinesNameFileAndLine) {
  const std::vector<BadTextCase> cases = {
      {"cameras.txt", "# c\n1 PINHOLE 640 480 500 500 320\n", "takes 4 parameters", 2},
      {"cameras.txt", "1 NOT_A_MODEL 640 480 1 2 3\n", "unknown camera model", 1},
      {"cameras.txt", "1 PINHOLE 640 480 500 abc 320 240\n", "finite number", 1},
      {"cameras.txt", "1 PINHOLE 0 480 500 500 320 240\n", "implausible size", 1},
      {"cameras.txt", "1 PINHOLE 640\n", "expected", 1},
      {"cameras.txt", "1 PINHOLE 640 480 1 1 1 1\n1 PINHOLE 640 480 1 1 1 1\n", "duplicate", 2},
      {"images.txt", "1 1 0 0 0 0 0 0 1\n", "expected", 1},
      {"images.txt", "1 1 0 0 0 0 0 0 1 a.png\n1 2\n", "triples", 2},
      {"images.txt", "1 0 0 0 0 0 0 0 1 a.png\n\n", "quaternion", 1},
      {"images.txt", "\n\n1 1 0 0 0 0 0 0 1 a.png\n1 2 -7\n", "negative", 4},
      {"points3D.txt", "1 0 0 0 255 255 255 0.5 1\n", "pairs", 1},
      {"points3D.txt", "1 0 0 0 256 0 0 0.5\n", "above 255", 1},
      {"points3D.txt", "1 0 0 nan 0 0 0 0.5\n", "finite", 1},
  };
  for (const auto& c : cases) {
    std::istringstream in(c.text);
    const std::string error = testing::InputErrorMessage([&] {
      if (c.file == "cameras.txt") ReadCamerasText(in, c.file);
      if (c.file == "images.txt") ReadImagesText(in, c.file);
      if (c.file == "points3D.txt") ReadPoints3DText(in, c.file);
    });
    EXPECT_EQ(error.rfind(c.file + ":" + std::to_string(c.line) + ":", 0), 0u)
        << "case '" << c.text << "' gave '" << error << "'";
    EXPECT_NE(error.find(c.expected), std::string::npos) << error;
  }
}

TEST(ColmapIoBadInput, DanglingReferencesAreRefused) {
  TempDir tmp;
  Reconstruction r = MakeTestReconstruction();
  r.images.begin()->second.camera_id = CameraId(999);
  WriteModel(r, tmp.path(), ModelFormat::kBinary);
  EXPECT_NE(testing::InputErrorMessage([&] { ReadModel(tmp.path()); }).find("camera 999"),
            std::string::npos);

  r = MakeTestReconstruction();
  r.points3d.begin()->second.track.push_back({ImageId(1), 100000});
  WriteModel(r, tmp.path(), ModelFormat::kText);
  std::filesystem::remove(tmp / "cameras.bin");
  EXPECT_NE(testing::InputErrorMessage([&] { ReadModel(tmp.path()); }).find("feature 100000"),
            std::string::npos);
}

// A COLMAP workspace as `colmap mapper` leaves it: models in sparse/0, sparse/1, ...
TEST(ColmapWorkspace, RootSparseAndModelFolderAllFindTheModelWithTheMostImages) {
  TempDir tmp;
  const Reconstruction r = MakeTestReconstruction();
  Reconstruction smaller = r;
  smaller.images.erase(std::prev(smaller.images.end()));
  for (auto& [id, point] : smaller.points3d) {
    std::erase_if(point.track,
                  [&](const TrackElement& e) { return !smaller.images.count(e.image_id); });
  }
  WriteModel(smaller, tmp / "ws/sparse/0", ModelFormat::kBinary);
  WriteModel(r, tmp / "ws/sparse/1", ModelFormat::kText);
  std::filesystem::create_directories(tmp / "ws/images");
  for (const auto& given : {tmp / "ws", tmp / "ws/sparse"}) {
    const LoadedModel loaded = ReadModel(given);
    EXPECT_EQ(loaded.folder, tmp / "ws/sparse/1") << given;
    EXPECT_EQ(loaded.reconstruction.images.size(), r.images.size());
    EXPECT_NE(loaded.choice.find("found 2 COLMAP models"), std::string::npos) << loaded.choice;
    EXPECT_NE(loaded.choice.find("registers the most images"), std::string::npos);
  }
  const LoadedModel direct = ReadModel(tmp / "ws/sparse/0");
  EXPECT_EQ(direct.folder, tmp / "ws/sparse/0");
  EXPECT_EQ(direct.choice, "");
  // A model written straight into sparse/ (model_converter) is taken alone.
  WriteModel(r, tmp / "ws2/sparse", ModelFormat::kBinary);
  EXPECT_EQ(ReadModel(tmp / "ws2").folder, tmp / "ws2/sparse");
}

TEST(ColmapWorkspace, ADamagedModelIsSkippedAndNamed) {
  TempDir tmp;
  WriteModel(MakeTestReconstruction(), tmp / "sparse/0", ModelFormat::kBinary);
  WriteModel(MakeTestReconstruction(), tmp / "sparse/1", ModelFormat::kBinary);
  WriteText(tmp / "sparse/1/images.bin", "");
  const ModelFolderChoice found = FindModelFolder(tmp.path());
  EXPECT_EQ(found.folder, tmp / "sparse/0");
  EXPECT_NE(found.choice.find("skipped"), std::string::npos) << found.choice;
  EXPECT_NE(found.choice.find("sparse/1/images.bin"), std::string::npos) << found.choice;
}

TEST(ColmapWorkspace, EqualModelsTakeTheLowestNumber) {
  TempDir tmp;
  const Reconstruction r = MakeTestReconstruction();
  for (const char* n : {"10", "2", "3"}) WriteModel(r, tmp / "sparse" / n, ModelFormat::kBinary);
  EXPECT_EQ(FindModelFolder(tmp.path()).folder, tmp / "sparse/2");
}

TEST(ColmapIoBadInput, AWorkspaceWithoutAModelSaysWhereItLooked) {
  TempDir tmp;
  std::filesystem::create_directories(tmp / "ws/sparse/0");
  std::filesystem::create_directories(tmp / "ws/images");
  const std::string message = testing::InputErrorMessage([&] { ReadModel(tmp / "ws"); });
  EXPECT_NE(message.find("no COLMAP model found"), std::string::npos) << message;
  EXPECT_NE(message.find("sparse/"), std::string::npos) << message;
}

TEST(ColmapIoBadInput, MissingFolderOrFilesAreNamed) {
  TempDir tmp;
  EXPECT_NE(
      testing::InputErrorMessage([&] { ReadModel(tmp / "nope"); }).find("model folder not found"),
      std::string::npos);
  WriteText(tmp / "cameras.txt", "");
  EXPECT_NE(
      testing::InputErrorMessage([&] { ReadModel(tmp.path()); }).find("no COLMAP model found"),
      std::string::npos);
  EXPECT_NE(testing::InputErrorMessage([&] {
              DetectModelFormat(tmp.path());
            }).find("not a COLMAP model folder"),
            std::string::npos);
}

}  // namespace
}  // namespace texlume::sfm
