#include "ptm/exr_io.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "core/bounded_memory_reader.h"
#include "core/check.h"
#include "core/errors.h"
#include "core/file_util.h"
#include "core/memory_budget.h"
#include "core/partial_output.h"

namespace texlume::ptm {
namespace {
// The most values (width x height x channels) ReadExr accepts: 8 Gi floats, enough for
// the largest atlas texlume writes (16,384 a side, 18 channels: 4.8 Gi); the memory
// limit (8 bytes a value) decides below that.
constexpr std::uint64_t kMaxExrValues = std::uint64_t{1} << 33;
// The widest and tallest EXR ReadExr accepts, checked in the header and in the spec.
constexpr std::int64_t kMaxExrSide = 1 << 16;
}  // namespace

void WriteExr(const std::filesystem::path& path, const std::vector<cv::Mat>& planes,
              const std::vector<std::string>& channel_names,
              const std::map<std::string, float>& float_attributes) {
  TEXLUME_CHECK(!planes.empty() && planes.size() == channel_names.size(), "one name per plane");
  const int width = planes[0].cols, height = planes[0].rows;
  for (const cv::Mat& p : planes) {
    TEXLUME_CHECK(p.type() == CV_32FC1 && p.cols == width && p.rows == height,
                  "EXR planes are CV_32FC1 of one size");
  }
  const int channels = static_cast<int>(planes.size());
  std::vector<float> interleaved(static_cast<std::size_t>(width) * height * channels);
  for (int y = 0; y < height; ++y) {
    for (int c = 0; c < channels; ++c) {
      const float* row = planes[static_cast<std::size_t>(c)].ptr<float>(y);
      for (int x = 0; x < width; ++x) {
        interleaved[(static_cast<std::size_t>(y) * width + x) * channels + c] = row[x];
      }
    }
  }
  // "<stem>.texlume-tmp-<pid>.exr": OpenImageIO picks the format by the extension.
  const std::filesystem::path tmp = TemporaryPathOf(path.parent_path() / path.stem()) += ".exr";
  RemoveStalePartials(path);
  auto out = OIIO::ImageOutput::create(tmp.string());
  if (!out) throw std::runtime_error(path.string() + ": OpenImageIO cannot write EXR");
  RegisterPartial(tmp);
  struct Cleanup {  // the temporary goes, whatever throws
    const std::filesystem::path& tmp;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      ForgetPartial(tmp);
    }
  } cleanup{tmp};
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
  spec.channelnames = channel_names;
  // PIZ (wavelet + Huffman), lossless: on a float PTM atlas it wrote 15 % fewer bytes
  // than ZIP in about half of ZIP's CPU time (docs/ptm_format.md, "Lossless EXR").
  spec.attribute("compression", "piz");
  // No capture date: the same data must give the same bytes.
  spec.attribute("DateTime", "");
  for (const auto& [name, value] : float_attributes) spec.attribute(name, value);
  const bool ok = out->open(tmp.string(), spec) &&
                  out->write_image(OIIO::TypeDesc::FLOAT, interleaved.data()) && out->close();
  if (!ok) throw std::runtime_error(path.string() + ": cannot write EXR: " + out->geterror());
  std::filesystem::rename(tmp, path);
}

namespace {

// The size a header declares, refused when implausible or beyond the memory limit.
void RequirePlausibleSize(std::int64_t width, std::int64_t height, std::int64_t channels,
                          const std::string& label) {
  if (width <= 0 || height <= 0 || channels <= 0 || width > kMaxExrSide || height > kMaxExrSide ||
      channels > 64) {
    throw InputError(label, "implausible image size or channel count");
  }
  const std::uint64_t values = static_cast<std::uint64_t>(width * height * channels);
  if (values > kMaxExrValues) {
    throw InputError(label, std::to_string(width) + " x " + std::to_string(height) + " x " +
                                std::to_string(channels) +
                                " channels is more than texlume reads (" +
                                std::to_string(kMaxExrValues >> 20) + " Mi values, " +
                                std::to_string((kMaxExrValues * 4) >> 30) + " GiB)");
  }
  RequireMemory(8.0 * static_cast<double>(values), "reading the EXR (values and planes)", label);
}

// The bytes of an OpenEXR header, read in order, each read checked against the bytes left.
class ExrHeaderReader {
 public:
  ExrHeaderReader(std::istream& in, std::uint64_t size, const std::string& label)
      : in_(in), left_(size), label_(label) {}

  void Read(char* out, std::uint64_t n) {
    if (n > left_ || !in_.read(out, static_cast<std::streamsize>(n))) {
      Refuse("its header is cut short");
    }
    left_ -= n;
  }
  std::int32_t Int32() {
    unsigned char b[4];
    Read(reinterpret_cast<char*>(b), 4);
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(b[0]) | (b[1] << 8) | (b[2] << 16) |
                                     (static_cast<std::uint32_t>(b[3]) << 24));
  }
  // A null-terminated attribute name or type name (at most 255 characters).
  std::string Name() {
    std::string name;
    for (char c = 0;;) {
      Read(&c, 1);
      if (c == '\0') return name;
      if (name.size() == 255) Refuse("an attribute name is longer than 255 characters");
      name += c;
    }
  }
  void Skip(std::int32_t n, const std::string& attribute) {
    if (n < 0 || static_cast<std::uint64_t>(n) > left_) {
      Refuse("attribute '" + attribute + "' declares " + std::to_string(n) +
             " bytes, more than the file holds");
    }
    in_.seekg(n, std::ios::cur);
    left_ -= static_cast<std::uint64_t>(n);
  }
  [[noreturn]] void Refuse(const std::string& why) const {
    throw InputError(label_, "is not a readable OpenEXR file: " + why);
  }

 private:
  std::istream& in_;
  std::uint64_t left_;
  const std::string& label_;
};

// The bytes OpenEXR 3.1 reads for an attribute of a fixed-size type, whatever size the
// file declares; 0 for a type whose size is the declared one or its own contents.
std::int32_t FixedAttributeBytes(const std::string& type) {
  static const std::map<std::string, std::int32_t> kFixed = {
      {"box2i", 16},      {"box2f", 16},   {"chromaticities", 32},
      {"compression", 1}, {"double", 8},   {"envmap", 1},
      {"float", 4},       {"int", 4},      {"keycode", 28},
      {"lineOrder", 1},   {"m33f", 36},    {"m33d", 72},
      {"m44f", 64},       {"m44d", 128},   {"rational", 8},
      {"tiledesc", 9},    {"timecode", 8}, {"v2i", 8},
      {"v2f", 8},         {"v2d", 16},     {"v3i", 12},
      {"v3f", 12},        {"v3d", 24},     {"deepImageState", 1}};
  const auto it = kFixed.find(type);
  return it == kFixed.end() ? 0 : it->second;
}

// A channel list as OpenEXR reads it (names until an empty one, 16 bytes each after its
// name), which must take exactly the bytes the attribute declares.
// Returns the number of channels.
int CheckChannelList(ExrHeaderReader& header, std::int32_t bytes) {
  std::int64_t read = 0;
  int channels = 0;
  for (std::string name = header.Name();; name = header.Name()) {
    read += static_cast<std::int64_t>(name.size()) + 1;
    if (name.empty()) break;
    char layout[16];
    header.Read(layout, sizeof layout);
    read += 16;
    ++channels;
  }
  if (read != bytes) header.Refuse("its channel list does not take the bytes it declares");
  return channels;
}

// A string vector as OpenEXR reads it (a length, then the characters), within its bytes.
void CheckStringVector(ExrHeaderReader& header, std::int32_t bytes) {
  for (std::int64_t read = 0; read < bytes;) {
    const std::int32_t length = header.Int32();
    read += 4;
    if (length < 0 || read + length > bytes) header.Refuse("a string vector overruns its bytes");
    header.Skip(length, "stringvector");
    read += length;
  }
}

// OpenEXR's header (openexr.com, "OpenEXR File Layout"), checked before OpenImageIO's
// reader sees the file: OpenEXR allocates an attribute's value by the size the file
// declares before it finds the file shorter (a 352-byte file declaring a 777 MB string
// took 893 MB and 2.9 s), reads typed attributes by their type rather than their declared
// size, and sizes its chunk table by the data window. So: the magic number, version 2 of a
// single-part image that is not deep, every attribute within the bytes that follow it and
// its declared size the size OpenEXR reads, and a data window of at most 65,536 a side
// whose values, with its channels, fit texlume's limits and memory budget.
void CheckExrHeader(std::istream& in, std::uint64_t size, const std::string& label) {
  ExrHeaderReader header(in, size, label);
  constexpr std::int32_t kMagic = 20000630;
  constexpr std::int32_t kKnownFlags = 0x200 | 0x400;  // tiled, long names
  if (size < 8 || header.Int32() != kMagic) {
    throw InputError(label, "is not an OpenEXR file (no magic number)");
  }
  const std::int32_t version = header.Int32();
  if ((version & 0xff) != 2 || (version & ~0xff & ~kKnownFlags) != 0) {
    throw InputError(label, "is an OpenEXR file texlume does not read (version field " +
                                std::to_string(version) + ": multi-part or deep)");
  }
  std::int64_t width = 0, height = 0;
  int channels = 0;
  for (std::string name = header.Name(); !name.empty(); name = header.Name()) {
    const std::string type = header.Name();
    const std::int32_t bytes = header.Int32();
    const std::int32_t fixed = FixedAttributeBytes(type);
    if (fixed != 0 && bytes != fixed) {
      header.Refuse("attribute '" + name + "' of type " + type + " declares " +
                    std::to_string(bytes) + " bytes, not " + std::to_string(fixed));
    }
    if (type == "preview" || type == "idmanifest") {
      header.Refuse("attribute '" + name + "' is of type " + type +
                    ", which texlume does not read");
    } else if (type == "chlist") {
      channels = CheckChannelList(header, bytes);
    } else if (type == "stringvector") {
      CheckStringVector(header, bytes);
    } else if (name == "dataWindow" && type == "box2i") {
      std::int32_t box[4];
      for (std::int32_t& v : box) v = header.Int32();
      width = std::int64_t{box[2]} - box[0] + 1;
      height = std::int64_t{box[3]} - box[1] + 1;
      if (width < 1 || height < 1 || width > kMaxExrSide || height > kMaxExrSide) {
        header.Refuse("its data window of " + std::to_string(width) + " x " +
                      std::to_string(height) + " pixels is beyond 65536 a side");
      }
    } else {
      header.Skip(bytes, name);
    }
  }
  // OpenEXR sizes its line buffers by the data window and channels when it opens the file.
  if (width > 0 && height > 0 && channels > 0) RequirePlausibleSize(width, height, channels, label);
}

// The OpenEXR reader only, on a file or on bytes in memory: a damaged file is refused
// by it rather than probed by every other format's reader.
std::unique_ptr<OIIO::ImageInput> OpenExr(const std::string& label,
                                          OIIO::Filesystem::IOProxy* proxy) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::create("openexr");
  if (!in) throw std::runtime_error("OpenImageIO was built without its OpenEXR reader");
  if (proxy && !in->set_ioproxy(proxy)) {
    throw std::runtime_error("OpenImageIO's OpenEXR reader cannot read from memory");
  }
  OIIO::ImageSpec spec;
  if (!in->open(proxy ? std::string() : label, spec)) {
    std::string error = in->geterror();
    if (error.empty()) error = OIIO::geterror();
    throw InputError(label, "is not a readable OpenEXR file: " + error);
  }
  return in;
}

std::vector<cv::Mat> ReadPlanes(OIIO::ImageInput& in, const std::string& label,
                                std::vector<std::string>* channel_names,
                                std::map<std::string, float>* float_attributes = nullptr) {
  const OIIO::ImageSpec& spec = in.spec();
  RequirePlausibleSize(spec.width, spec.height, spec.nchannels, label);
  std::vector<float> data(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  if (!in.read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data())) {
    throw InputError(label, "cannot read pixels: " + in.geterror());
  }
  std::vector<cv::Mat> planes;
  for (int c = 0; c < spec.nchannels; ++c) {
    cv::Mat p(spec.height, spec.width, CV_32FC1);
    for (int y = 0; y < spec.height; ++y) {
      float* row = p.ptr<float>(y);
      for (int x = 0; x < spec.width; ++x) {
        row[x] = data[(static_cast<std::size_t>(y) * spec.width + x) * spec.nchannels + c];
      }
    }
    planes.push_back(p);
  }
  if (channel_names) *channel_names = spec.channelnames;
  if (float_attributes) {
    float_attributes->clear();
    for (const OIIO::ParamValue& p : spec.extra_attribs)
      if (p.type() == OIIO::TypeFloat && p.name().string().rfind("texlume:", 0) == 0)
        (*float_attributes)[p.name().string()] = p.get_float();
  }
  return planes;
}

}  // namespace

std::vector<cv::Mat> ReadExr(const std::filesystem::path& path,
                             std::vector<std::string>* channel_names,
                             std::map<std::string, float>* float_attributes) {
  {
    std::ifstream file = OpenForReading(path, true);
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) throw InputError(path.string(), "cannot be read: " + ec.message());
    CheckExrHeader(file, size, path.string());
  }
  const std::unique_ptr<OIIO::ImageInput> in = OpenExr(path.string(), nullptr);
  return ReadPlanes(*in, path.string(), channel_names, float_attributes);
}

std::vector<cv::Mat> ReadExrBytes(std::string_view bytes, const std::string& label,
                                  std::vector<std::string>* channel_names) {
  {
    std::istringstream header{std::string(bytes)};
    CheckExrHeader(header, bytes.size(), label);
  }
  BoundedMemoryReader memory(bytes);
  const std::unique_ptr<OIIO::ImageInput> in = OpenExr(label, &memory);
  return ReadPlanes(*in, label, channel_names);
}

}  // namespace texlume::ptm
