#include "report/report.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "core/provenance.h"
#include "tests/test_util.h"

namespace texlume::report {
namespace {
namespace fs = std::filesystem;

std::vector<std::string> Links(const std::string& html) {
  std::vector<std::string> links;
  for (const std::string attribute : {"src=\"", "href=\""})
    for (std::size_t at = html.find(attribute); at != std::string::npos;
         at = html.find(attribute, at + 1)) {
      const std::size_t begin = at + attribute.size();
      links.push_back(html.substr(begin, html.find('"', begin) - begin));
    }
  return links;
}

// One triangle on a 16 x 16 atlas of a flat grey PTM.
model::TexturedModel OneTriangle() {
  model::TexturedModel m;
  m.mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.mesh.faces = {{0, 1, 2}};
  m.corner_px = {{Eigen::Vector2f(1, 15), Eigen::Vector2f(15, 15), Eigen::Vector2f(1, 1)}};
  m.face_atlas = {0};
  ptm::Ptm atlas;
  atlas.Resize(ptm::PtmFormat::kRgb, 16, 16);
  for (std::size_t t = 0; t < atlas.NumTexels(); ++t)
    for (int p = 0; p < 3; ++p) atlas.coefficients[(t * 3 + p) * 6 + 5] = 0.5f;  // a5: constant
  m.atlases = {atlas};
  return m;
}

// A view whose reference and drawings are all `grey`, seen everywhere.
render::ViewPictures GreyView(const cv::Mat& grey, std::vector<render::ViewPictures::Drawn> drawn) {
  render::ViewPictures view;
  view.name = "view_0.png";
  view.reference = grey;
  view.inside = cv::Mat(grey.rows, grey.cols, CV_8UC1, cv::Scalar(255));
  view.drawn = std::move(drawn);
  return view;
}

// The report lays out pictures and metrics it is given: every picture it links
// exists, the metrics shown are the given ones (it measures nothing), and
// text is escaped.
TEST(WriteReport, ShowsTheGivenPicturesAndMetricsAndLinksOnlyWhatItWrote) {
  const model::TexturedModel model = OneTriangle();
  ReportInputs in;
  in.title = "a <stone> & \"sphere\"";
  in.model = &model;
  in.occupancy = 0.5;
  const cv::Mat grey(24, 32, CV_32FC3, cv::Scalar::all(0.4));
  in.sample_relit = {{Eigen::Vector3d::UnitZ(), grey}, {Eigen::Vector3d::UnitX(), grey}};
  in.sample_width = 32;
  in.sample_height = 24;
  const render::ViewPictures view =
      GreyView(grey, {{"texlume", grey, 31.25, 0.875}, {"flat", grey, 12.5, 0.25}});
  in.views = {view, view};
  in.views_total = 5;
  in.views_heading = "Held-out views";
  in.sweep = {grey, grey, grey, grey};
  in.sweep_view = view.name;
  in.metrics = {{"texlume", {{"view_0.png", 22.5, 0.5, 23.5, 0.625, {}}}, 22.5, 0.5, 23.5, 0.625}};
  testing::TempDir out;
  const ReportSummary s = WriteReport(out.path(), in);
  const std::string html = testing::ReadText(out.path() / "report.html");
  EXPECT_NE(html.find("a &lt;stone&gt; &amp; &quot;sphere&quot;"), std::string::npos);
  EXPECT_NE(html.find("2 of 5 views"), std::string::npos);
  EXPECT_NE(html.find("31.25 dB, SSIM 0.875"), std::string::npos);
  EXPECT_NE(html.find("22.50"), std::string::npos);
  for (const std::string& link : Links(html)) EXPECT_TRUE(fs::exists(out.path() / link)) << link;
  // 2 sample, the error scale, 2 x (reference + 2 models + 2 errors), the sweep, 1 atlas.
  EXPECT_EQ(s.pictures, 2u + 1u + 2u * 5u + 1u + 1u);
  EXPECT_EQ(cv::imread((out.path() / "report/error_scale.png").string()).cols, 256);
  ASSERT_EQ(s.rows.size(), 4u);
  EXPECT_EQ(s.rows[0].psnr, 31.25);
  EXPECT_EQ(s.rows[1].model, "flat");
  EXPECT_EQ(cv::imread((out.path() / "report/light_sweep.png").string()).cols, 4 * 32);
  const std::vector<double> occupancy = AtlasOccupancies(model);
  ASSERT_EQ(occupancy.size(), 1u);
  // Every texel whose centre is inside counts (1 + ... + 14 of them), and no
  // texel beyond the triangle grown by one texel (1 + ... + 16).
  EXPECT_GE(occupancy[0], 105.0 / 256.0);
  EXPECT_LE(occupancy[0], 136.0 / 256.0);
}

// With the texel size and the world unit given, the page gives each texel's and each view
// pixel's length on the object, and the pictures carry a scale bar of a 1-2-5 length.
TEST(WriteReport, GivesThePhysicalScaleOfTheSampleTheAtlasesAndTheViews) {
  const model::TexturedModel model = OneTriangle();
  ReportInputs in;
  in.model = &model;
  in.texel_size = 0.5;
  in.mm_per_world_unit = 1.0;
  // 400 sample texels shown in 200 pixels: 1 world unit (1 mm) per pixel, so a quarter of
  // the width (50 pixels) holds a bar of 50 mm.
  const cv::Mat grey(100, 200, CV_32FC3, cv::Scalar::all(0.4));
  in.sample_relit = {{Eigen::Vector3d::UnitZ(), grey}};
  in.sample_width = 400;
  in.sample_height = 200;
  render::ViewPictures view = GreyView(grey, {{"texlume", grey, 20.0, 0.5}});
  view.world_per_pixel = 0.25;
  in.views = {view};
  testing::TempDir out;
  WriteReport(out.path(), in);
  std::string html = testing::ReadText(out.path() / "report.html");
  EXPECT_NE(html.find("texel spans 0.5 world units (0.5 mm) on the object"), std::string::npos);
  EXPECT_NE(html.find("1 pixel: 0.25 world units (0.25 mm) at the model's centre"),
            std::string::npos);
  const cv::Mat sample = cv::imread((out.path() / "report/sample_light_0.png").string());
  const int bar_row = sample.rows - 8;
  EXPECT_EQ(sample.at<cv::Vec3b>(bar_row, 7), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(sample.at<cv::Vec3b>(bar_row, 55), cv::Vec3b(255, 255, 255));
  EXPECT_NE(sample.at<cv::Vec3b>(bar_row, 60), cv::Vec3b(255, 255, 255));  // 50 pixels long
  EXPECT_NE(sample.at<cv::Vec3b>(20, 150), cv::Vec3b(255, 255, 255));
  const cv::Mat reference = cv::imread((out.path() / "report/view_0_reference.png").string());
  // 0.25 mm per pixel: 12.5 mm fit in a quarter, the bar is 10 mm = 40 pixels.
  EXPECT_EQ(reference.at<cv::Vec3b>(bar_row, 45), cv::Vec3b(255, 255, 255));
  EXPECT_NE(reference.at<cv::Vec3b>(bar_row, 50), cv::Vec3b(255, 255, 255));
  // Without the world unit, lengths are in world units and the page says why.
  in.mm_per_world_unit = 0.0;
  WriteReport(out.path(), in);
  html = testing::ReadText(out.path() / "report.html");
  EXPECT_NE(html.find("texel spans 0.5 world units on the object"), std::string::npos);
  EXPECT_NE(html.find("no --world-unit was given"), std::string::npos);
}

// The page says where a baseline measures better than texlume, points to texlume view,
// and names texlume's version and the inputs with their checksums.
TEST(WriteReport, SaysWhereABaselineWinsAndWhereTheResultsCameFrom) {
  const model::TexturedModel model = OneTriangle();
  testing::TempDir out;
  testing::WriteText(out / "lights.json", "123456789");  // CRC-32 check value cbf43926
  ReportInputs in;
  in.model = &model;
  in.inputs = {{"lights", out / "lights.json"}};
  in.view_folder = "model dir";
  // The zenith at the centre; azimuth 90 degrees at 30 degrees of elevation, up the plot.
  in.light_plots = {{"capture",
                     "sample frame",
                     {Eigen::Vector3d::UnitZ(), Eigen::Vector3d(0, std::cos(M_PI / 6), 0.5)}}};
  in.metrics = {{"texlume", {}, 22.5, 0.60, 23.5, 0.70}, {"flat", {}, 23.0, 0.40, 23.0, 0.30}};
  WriteReport(out.path(), in);
  std::string html = testing::ReadText(out.path() / "report.html");
  EXPECT_NE(html.find("flat beats texlume in PSNR (23.00 against 22.50)"), std::string::npos)
      << html;
  EXPECT_EQ(html.find("flat beats texlume in SSIM"), std::string::npos);
  EXPECT_NE(html.find("texlume view model dir"), std::string::npos);
  EXPECT_NE(html.find(std::string("<td>") + TexlumeVersion() + "</td>"), std::string::npos);
  EXPECT_NE(html.find("CRC-32 cbf43926"), std::string::npos);
  EXPECT_NE(html.find("<circle cx=\"110.0\" cy=\"110.0\" r=\"3.5\""), std::string::npos) << html;
  EXPECT_NE(html.find("<circle cx=\"110.0\" cy=\"43.3\" r=\"3.5\""), std::string::npos) << html;
  EXPECT_NE(html.find("capture (2): sample frame"), std::string::npos);
  in.metrics[1].mean_psnr = 20.0;
  WriteReport(out.path(), in);
  html = testing::ReadText(out.path() / "report.html");
  EXPECT_NE(html.find("texlume measures best in every figure"), std::string::npos);
}

TEST(Provenance, TheCommandLineIsRecordedQuotedAsAShellReadsIt) {
  const char* argv[] = {"texlume", "synth", "--out", "my model", "it's"};
  RecordCommandLine(5, argv);
  EXPECT_EQ(RecordedCommandLine(), "texlume synth --out 'my model' 'it'\\''s'");
}

// A photo that cannot be read: an error naming it, the earlier report kept.
TEST(WriteReport, AFailureKeepsTheEarlierReportWhole) {
  const model::TexturedModel model = OneTriangle();
  ReportInputs in;
  in.model = &model;
  testing::TempDir out;
  WriteReport(out.path(), in);
  const std::string before = testing::ReadText(out.path() / "report.html");
  in.photos = {{"missing.png", out.path() / "missing.png", {}, {}}};
  EXPECT_THROW(WriteReport(out.path(), in), InputError);
  EXPECT_EQ(testing::ReadText(out.path() / "report.html"), before);
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(out.path())) ++entries;
  EXPECT_EQ(entries, 2u);  // report.html and report/
}

TEST(HtmlEscape, EscapesTheFiveCharacters) {
  EXPECT_EQ(HtmlEscape("<a href='x'>&\"</a>"), "&lt;a href=&#39;x&#39;&gt;&amp;&quot;&lt;/a&gt;");
}

}  // namespace
}  // namespace texlume::report
