// Reading map_server maps (see map_read.h).
#include "sdpslam/io/map_read.h"

#include <png.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <new>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace sdpslam::io {
namespace {

// Either side of an image, in pixels (PGM and PNG alike).
constexpr long kMaxImageSide = 100000;
// zlib's deflate expands by at most 1032:1 (zlib.net, "Technical Details") and a PNG pixel
// takes at least one bit: a PNG of n bytes holds at most 8 * 1032 * n pixels.
constexpr std::size_t kMaxPngPixelsPerByte = 8U * 1032U;

bool fail(std::string* error, const std::string& where, const std::string& why) {
  if (error != nullptr) *error = where + ": " + why;
  return false;
}

// "name:line" of a yaml-cpp mark (its lines count from 0), "name" where it has none.
std::string at(const std::string& name, const YAML::Mark& mark) {
  if (mark.is_null() || mark.line < 0) return name;
  return name + ":" + std::to_string(mark.line + 1);
}

bool finite_real(const YAML::Node& node, double* out) {
  double v = 0.0;
  if (!node.IsScalar() || !YAML::convert<double>::decode(node, v) || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

// ---- pixels to cells -------------------------------------------------------------------

// The float kept for occupancy p stays in the class p has in double: above
// occupied_thresh, below free_thresh, or between them. Rounding to float moves a value by
// at most half a step, so one step back past p restores the class.
float keep_class(double p, const MapWriteOptions& t) {
  float kept = static_cast<float>(p);
  if (p > t.occupied_thresh) {
    if (!(kept > t.occupied_thresh)) kept = std::nextafter(kept, 2.0F);
  } else if (p < t.free_thresh) {
    if (!(kept < t.free_thresh)) kept = std::nextafter(kept, -1.0F);
  } else if (kept > t.occupied_thresh) {
    kept = std::nextafter(kept, -1.0F);
  } else if (kept < t.free_thresh) {
    kept = std::nextafter(kept, 2.0F);
  }
  return kept;
}

// One pixel: `colour_sum` is red + green + blue (three times the grey level of a grey
// image), each in 0..max; `alpha` its opacity in 0..max (max for an image without alpha).
float cell_of(std::uint32_t colour_sum, std::uint32_t alpha, std::uint32_t max, bool has_alpha, const MapYaml& yaml) {
  const MapWriteOptions& t = yaml.thresholds;
  if (yaml.mode == MapMode::kRaw) {
    const long percent = std::lround(255.0 * static_cast<double>(colour_sum) / (3.0 * static_cast<double>(max)));
    return percent <= 100 ? keep_class(static_cast<double>(percent) / 100.0, t) : -1.0F;
  }
  if (yaml.mode == MapMode::kScale && has_alpha && alpha != max) return -1.0F;
  std::uint32_t total = colour_sum;
  std::uint32_t total_max = 3U * max;
  if (yaml.mode == MapMode::kTrinary && has_alpha) {
    total += alpha;
    total_max += max;
  }
  // One rounding only: (max - v) / max, not 1 - v / max (8/40 is the double nearest 0.2;
  // 1 - 32/40 is below it).
  const std::uint32_t level = t.negate ? total : total_max - total;
  const double p = static_cast<double>(level) / static_cast<double>(total_max);
  // map_server's rule: occupied iff p > occupied_thresh, free iff p < free_thresh (a
  // pixel exactly on a threshold is neither).
  if (yaml.mode == MapMode::kTrinary && !(p > t.occupied_thresh) && !(p < t.free_thresh)) return -1.0F;
  return keep_class(p, t);
}

OccupancyImage empty_map(const MapYaml& yaml, long w, long h) {
  OccupancyImage m;
  m.width = static_cast<std::uint32_t>(w);
  m.height = static_cast<std::uint32_t>(h);
  m.resolution_m = yaml.resolution_m;
  m.origin_x_m = yaml.origin_x_m;
  m.origin_y_m = yaml.origin_y_m;
  m.occupancy.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), -1.0F);
  return m;
}

// ---- PGM ------------------------------------------------------------------------------

// Next whitespace-separated token of a PGM header, skipping '#' comments.
bool pgm_token(const std::string& data, std::size_t* pos, std::string* token) {
  while (*pos < data.size()) {
    const char c = data[*pos];
    if (c == '#') {
      while (*pos < data.size() && data[*pos] != '\n') ++*pos;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
      ++*pos;
    } else {
      break;
    }
  }
  const std::size_t start = *pos;
  while (*pos < data.size() && data[*pos] != ' ' && data[*pos] != '\t' && data[*pos] != '\r' && data[*pos] != '\n') {
    ++*pos;
  }
  *token = data.substr(start, *pos - start);
  return !token->empty();
}

bool decode_pgm(const std::string& data, const std::string& name, const MapYaml& yaml, OccupancyImage* map,
                std::string* error) {
  std::size_t pos = 0U;
  std::string magic, ws, hs, ms;
  pgm_token(data, &pos, &magic);
  if (!pgm_token(data, &pos, &ws) || !pgm_token(data, &pos, &hs) || !pgm_token(data, &pos, &ms)) {
    return fail(error, name, "truncated header");
  }
  const long w = std::strtol(ws.c_str(), nullptr, 10);
  const long h = std::strtol(hs.c_str(), nullptr, 10);
  const long maxval = std::strtol(ms.c_str(), nullptr, 10);
  if (w <= 0 || h <= 0 || w > kMaxImageSide || h > kMaxImageSide) return fail(error, name, "bad size " + ws + " x " + hs);
  if (maxval <= 0 || maxval > 255) return fail(error, name, "maxval must be 1..255");
  ++pos;  // the single whitespace after maxval (absent at the end of a file without pixels)
  const std::size_t cells = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const std::size_t have = data.size() > pos ? data.size() - pos : 0U;
  if (have < cells) {
    return fail(error, name, "image data short: " + std::to_string(have) + " of " + std::to_string(cells) + " bytes");
  }
  OccupancyImage m = empty_map(yaml, w, h);
  const auto max = static_cast<std::uint32_t>(maxval);
  for (std::uint32_t r = 0; r < m.height; ++r) {
    const std::size_t src = pos + static_cast<std::size_t>(r) * m.width;
    const std::size_t dst = static_cast<std::size_t>(m.height - 1U - r) * m.width;  // row 0 is the top
    for (std::uint32_t c = 0; c < m.width; ++c) {
      const std::uint32_t pixel = static_cast<unsigned char>(data[src + c]);
      if (pixel > max) {
        // Netpbm: "each gray value is a number from 0 through maxval".
        return fail(error, name,
                    "pixel " + std::to_string(src + c - pos) + " is " + std::to_string(pixel) + ", above maxval " +
                        std::to_string(maxval));
      }
      m.occupancy[dst + c] = cell_of(3U * pixel, max, max, false, yaml);
    }
  }
  *map = std::move(m);
  return true;
}

// ---- PNG ------------------------------------------------------------------------------

// libpng's simplified API: every colour type and depth comes out as 8-bit RGB or RGBA
// (grey copied to the three channels, palettes expanded, 16 bits scaled), no setjmp.
class PngReader {
 public:
  PngReader() {
    std::memset(&image_, 0, sizeof image_);
    image_.version = PNG_IMAGE_VERSION;
  }
  ~PngReader() { png_image_free(&image_); }
  PngReader(const PngReader&) = delete;
  PngReader& operator=(const PngReader&) = delete;
  png_image& image() { return image_; }
  std::string message() const { return image_.message; }

 private:
  png_image image_;
};

bool decode_png(const std::string& data, const std::string& name, const MapYaml& yaml, OccupancyImage* map,
                std::string* error) {
  PngReader reader;
  png_image& image = reader.image();
  if (png_image_begin_read_from_memory(&image, data.data(), data.size()) == 0) {
    return fail(error, name, "cannot read PNG: " + reader.message());
  }
  const long w = static_cast<long>(image.width);
  const long h = static_cast<long>(image.height);
  if (w <= 0 || h <= 0 || w > kMaxImageSide || h > kMaxImageSide) {
    return fail(error, name, "bad size " + std::to_string(w) + " x " + std::to_string(h));
  }
  const std::size_t cells = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (cells / kMaxPngPixelsPerByte > data.size()) {
    return fail(error, name,
                std::to_string(w) + " x " + std::to_string(h) + " pixels cannot be held in " +
                    std::to_string(data.size()) + " bytes");
  }
  const bool has_alpha = (image.format & PNG_FORMAT_FLAG_ALPHA) != 0U;
  image.format = has_alpha ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
  const std::size_t channels = has_alpha ? 4U : 3U;
  std::vector<png_byte> px(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, px.data(), 0, nullptr) == 0) {
    return fail(error, name, "cannot read PNG: " + reader.message());
  }
  OccupancyImage m = empty_map(yaml, w, h);
  for (std::uint32_t r = 0; r < m.height; ++r) {
    const png_byte* row = px.data() + static_cast<std::size_t>(r) * m.width * channels;
    const std::size_t dst = static_cast<std::size_t>(m.height - 1U - r) * m.width;  // row 0 is the top
    for (std::uint32_t c = 0; c < m.width; ++c) {
      const png_byte* p = row + static_cast<std::size_t>(c) * channels;
      const std::uint32_t colour_sum = static_cast<std::uint32_t>(p[0]) + p[1] + p[2];
      const std::uint32_t alpha = has_alpha ? p[3] : 255U;
      m.occupancy[dst + c] = cell_of(colour_sum, alpha, 255U, has_alpha, yaml);
    }
  }
  *map = std::move(m);
  return true;
}

}  // namespace

bool parse_map_yaml(std::istream& text, const std::string& name, MapYaml* out, std::string* error) {
  try {
    const YAML::Node doc = YAML::Load(text);
    if (!doc.IsMap()) return fail(error, at(name, doc.Mark()), "not a YAML mapping (image: ..., resolution: ...)");
    MapYaml y;

    const YAML::Node image = doc["image"];
    if (!image) return fail(error, name, "no 'image' key");
    if (!image.IsScalar() || image.Scalar().empty()) return fail(error, at(name, image.Mark()), "image must be a file name");
    y.image = image.Scalar();

    const YAML::Node resolution = doc["resolution"];
    if (!resolution) return fail(error, name, "no 'resolution' key");
    if (!finite_real(resolution, &y.resolution_m) || !(y.resolution_m > 0.0)) {
      return fail(error, at(name, resolution.Mark()), "resolution must be > 0");
    }

    const YAML::Node origin = doc["origin"];
    if (!origin) return fail(error, name, "no 'origin' key");
    double yaw = 0.0;
    if (!origin.IsSequence() || origin.size() != 3U || !finite_real(origin[0], &y.origin_x_m) ||
        !finite_real(origin[1], &y.origin_y_m) || !finite_real(origin[2], &yaw)) {
      return fail(error, at(name, origin.Mark()), "origin must be [x, y, yaw]");
    }
    if (yaw != 0.0) return fail(error, at(name, origin.Mark()), "a rotated origin (yaw != 0) is not supported");

    if (const YAML::Node negate = doc["negate"]) {
      // nav2's map_io reads negate as an int, else as a bool.
      int i = 0;
      bool b = false;
      if (negate.IsScalar() && YAML::convert<int>::decode(negate, i) && (i == 0 || i == 1)) {
        y.thresholds.negate = i == 1;
      } else if (negate.IsScalar() && YAML::convert<bool>::decode(negate, b)) {
        y.thresholds.negate = b;
      } else {
        return fail(error, at(name, negate.Mark()), "negate must be 0, 1, false or true");
      }
    }
    if (const YAML::Node occupied = doc["occupied_thresh"]) {
      if (!finite_real(occupied, &y.thresholds.occupied_thresh)) {
        return fail(error, at(name, occupied.Mark()), "occupied_thresh is not a number");
      }
    }
    if (const YAML::Node free = doc["free_thresh"]) {
      if (!finite_real(free, &y.thresholds.free_thresh)) {
        return fail(error, at(name, free.Mark()), "free_thresh is not a number");
      }
    }
    if (const YAML::Node mode = doc["mode"]) {
      const std::string m = mode.IsScalar() ? mode.Scalar() : std::string();
      if (m == "trinary") {
        y.mode = MapMode::kTrinary;
      } else if (m == "scale") {
        y.mode = MapMode::kScale;
      } else if (m == "raw") {
        y.mode = MapMode::kRaw;
      } else {
        return fail(error, at(name, mode.Mark()), "mode must be trinary, scale or raw");
      }
    }
    const MapWriteOptions& t = y.thresholds;
    if (!(t.free_thresh >= 0.0 && t.free_thresh < t.occupied_thresh && t.occupied_thresh <= 1.0)) {
      return fail(error, name, "thresholds must satisfy 0 <= free_thresh < occupied_thresh <= 1");
    }
    *out = std::move(y);
    return true;
  } catch (const YAML::Exception& e) {
    return fail(error, at(name, e.mark), e.msg);
  }
}

bool decode_map_image(const std::string& bytes, const std::string& name, const MapYaml& yaml, OccupancyImage* map,
                      std::string* error) {
  try {
    if (bytes.size() >= 8U && png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) == 0) {
      return decode_png(bytes, name, yaml, map, error);
    }
    std::size_t pos = 0U;
    std::string magic;
    if (pgm_token(bytes, &pos, &magic) && magic == "P5") return decode_pgm(bytes, name, yaml, map, error);
    return fail(error, name, "not a binary PGM (P5) or a PNG image");
  } catch (const std::bad_alloc&) {
    // A legal image can be larger than this machine's memory (a PNG of a few MB can
    // inflate to 10^10 pixels).
    return fail(error, name, "the image does not fit in memory");
  }
}

bool read_map_yaml(const std::string& yaml_path, OccupancyImage* map, MapWriteOptions* thresholds,
                   std::string* error, MapYaml* yaml) {
  std::ifstream text(yaml_path);
  if (!text) return fail(error, yaml_path, "cannot open");
  MapYaml meta;
  if (!parse_map_yaml(text, yaml_path, &meta, error)) return false;
  std::string image_path = meta.image;
  const std::size_t slash = yaml_path.find_last_of('/');
  if (meta.image[0] != '/' && slash != std::string::npos) image_path = yaml_path.substr(0, slash + 1U) + meta.image;
  std::ifstream in(image_path, std::ios::binary);
  if (!in) return fail(error, image_path, "cannot open (named by " + yaml_path + ")");
  std::stringstream bytes;
  bytes << in.rdbuf();
  if (!decode_map_image(bytes.str(), image_path, meta, map, error)) return false;
  if (thresholds != nullptr) *thresholds = meta.thresholds;
  if (yaml != nullptr) *yaml = std::move(meta);
  return true;
}

}  // namespace sdpslam::io
