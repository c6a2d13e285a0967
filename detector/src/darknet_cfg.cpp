// SPDX-License-Identifier: MIT
// Darknet .cfg parser and writer, shape arithmetic, and DarknetModel::weight_count() / flops().
#include "wingman/detector/darknet_cfg.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

namespace wingman::detector {

namespace {

struct Entry {
  std::string key;
  std::string value;
  int line = 0;
};

struct Section {
  std::string name;
  int line = 0;
  std::vector<Entry> entries;
};

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

class SectionReader {
 public:
  SectionReader(const Section& section, const std::string& source) : s_(section), source_(source) {}

  [[noreturn]] void fail(int line, const std::string& what) const {
    throw DarknetFormatError(fmt::format("{}:{}: [{}] {}", source_, line, s_.name, what));
  }

  const Entry* find(const std::string& key) {
    used_.insert(key);
    const Entry* found = nullptr;
    for (const auto& e : s_.entries)
      if (e.key == key) found = &e;  // Darknet: the last occurrence wins
    return found;
  }

  int get_int(const std::string& key, int def) {
    const Entry* e = find(key);
    if (!e) return def;
    errno = 0;
    char* end = nullptr;
    const long v = std::strtol(e->value.c_str(), &end, 10);
    if (errno != 0 || end == e->value.c_str() || *end != '\0' || v < -1000000 || v > 1000000)
      fail(e->line, fmt::format("key '{}' = '{}': expected an integer", key, e->value));
    return static_cast<int>(v);
  }

  float get_float(const std::string& key, float def) {
    const Entry* e = find(key);
    if (!e) return def;
    errno = 0;
    char* end = nullptr;
    const float v = std::strtof(e->value.c_str(), &end);
    if (errno != 0 || end == e->value.c_str() || *end != '\0' || !std::isfinite(v))
      fail(e->line, fmt::format("key '{}' = '{}': expected a number", key, e->value));
    return v;
  }

  std::vector<float> get_floats(const std::string& key) {
    return get_list<float>(key, "a number", [](const char* text, char** end) { return std::strtof(text, end); });
  }

  std::vector<int> get_ints(const std::string& key) {
    return get_list<int>(key, "an integer",
                         [](const char* text, char** end) { return static_cast<int>(std::strtol(text, end, 10)); });
  }

  /// A comma-separated list of `key` (empty when the key is absent); `parse` is strtof/strtol-like.
  template <class T, class Parse>
  std::vector<T> get_list(const std::string& key, const char* what, Parse parse) {
    std::vector<T> out;
    const Entry* e = find(key);
    if (!e) return out;
    std::stringstream ss(e->value);
    std::string item;
    while (std::getline(ss, item, ',')) {
      item = trim(item);
      if (item.empty()) continue;
      char* end = nullptr;
      const T v = parse(item.c_str(), &end);
      if (end == item.c_str() || *end != '\0')
        fail(e->line, fmt::format("key '{}' = '{}': '{}' is not {}", key, e->value, item, what));
      out.push_back(v);
    }
    return out;
  }

  std::string get_string(const std::string& key, const std::string& def) {
    const Entry* e = find(key);
    return e ? e->value : def;
  }

  int line_of(const std::string& key) const {
    for (const auto& e : s_.entries)
      if (e.key == key) return e.line;
    return s_.line;
  }

  /// Every key that no getter asked for is an unsupported key.
  void check_all_used() const {
    for (const auto& e : s_.entries)
      if (!used_.count(e.key)) fail(e.line, fmt::format("unsupported key '{}'", e.key));
  }

 private:
  const Section& s_;
  const std::string& source_;
  std::set<std::string> used_;
};

std::vector<Section> split_sections(const std::string& text, const std::string& source) {
  std::vector<Section> sections;
  std::istringstream in(text);
  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    std::string line = raw;
    const auto hash = line.find_first_of("#;");
    if (hash != std::string::npos) line = line.substr(0, hash);
    line = trim(line);
    if (line.empty()) continue;
    if (line.front() == '[') {
      if (line.back() != ']')
        throw DarknetFormatError(fmt::format("{}:{}: section header '{}' lacks ']'", source, line_no, line));
      sections.push_back({trim(line.substr(1, line.size() - 2)), line_no, {}});
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos)
      throw DarknetFormatError(fmt::format("{}:{}: expected key=value, got '{}'", source, line_no, line));
    if (sections.empty())
      throw DarknetFormatError(
          fmt::format("{}:{}: key '{}' before the first section", source, line_no, trim(line.substr(0, eq))));
    std::string key = trim(line.substr(0, eq));
    // Darknet strips all whitespace from lines ("1.08,1.19,  3.42,4.41" and "leaky" alike).
    std::string value;
    for (char c : line.substr(eq + 1))
      if (c != ' ' && c != '\t') value.push_back(c);
    sections.back().entries.push_back({key, value, line_no});
  }
  return sections;
}

Activation parse_activation(SectionReader& r) {
  const std::string a = r.get_string("activation", "logistic");  // Darknet's default
  if (a == "leaky") return Activation::kLeaky;
  if (a == "linear") return Activation::kLinear;
  if (a == "logistic") return Activation::kLogistic;
  r.fail(r.line_of("activation"), fmt::format("key 'activation' = '{}': supported are leaky, linear, logistic", a));
}

const std::set<std::string>& net_training_keys() {
  static const std::set<std::string> keys = {
      "batch",  "subdivisions", "momentum", "decay",  "learning_rate", "burn_in",    "max_batches", "policy", "steps",
      "scales", "step",         "gamma",    "power",  "hue",           "saturation", "exposure",    "jitter", "angle",
      "aspect", "random",       "flip",     "mosaic", "max_crop",      "min_crop",   "time_steps",  "seed"};
  return keys;
}

[[noreturn]] void shape_error(const DarknetModel& m, const Layer& l, size_t index, const std::string& what) {
  throw DarknetFormatError(
      fmt::format("{}:{}: [{}] (layer {}) {}", m.cfg_path, l.cfg_line, layer_type_name(l.type), index, what));
}

std::string join_floats(const std::vector<float>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + fmt::format("{}", v[i]);
  return s;
}

std::string join_ints(const std::vector<int>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + std::to_string(v[i]);
  return s;
}

}  // namespace

const char* layer_type_name(LayerType type) {
  switch (type) {
    case LayerType::kConvolutional:
      return "convolutional";
    case LayerType::kMaxpool:
      return "maxpool";
    case LayerType::kRegion:
      return "region";
    case LayerType::kRoute:
      return "route";
    case LayerType::kUpsample:
      return "upsample";
    case LayerType::kYolo:
      return "yolo";
  }
  return "unknown";
}

const char* activation_name(Activation activation) {
  switch (activation) {
    case Activation::kLinear:
      return "linear";
    case Activation::kLeaky:
      return "leaky";
    case Activation::kLogistic:
      return "logistic";
  }
  return "unknown";
}

DarknetModel parse_darknet_cfg_string(const std::string& cfg_text, const std::string& source_name) {
  DarknetModel model;
  model.cfg_path = source_name;
  const std::vector<Section> sections = split_sections(cfg_text, source_name);
  if (sections.empty() || (sections.front().name != "net" && sections.front().name != "network"))
    throw DarknetFormatError(fmt::format("{}:{}: the first section must be [net]", source_name,
                                         sections.empty() ? 1 : sections.front().line));
  for (size_t si = 0; si < sections.size(); ++si) {
    const Section& s = sections[si];
    SectionReader r(s, source_name);
    if (si == 0) {
      model.net.width = r.get_int("width", 416);
      model.net.height = r.get_int("height", 416);
      model.net.channels = r.get_int("channels", 3);
      for (const auto& e : s.entries) {
        if (e.key == "width" || e.key == "height" || e.key == "channels") continue;
        if (!net_training_keys().count(e.key)) r.fail(e.line, fmt::format("unsupported key '{}'", e.key));
        model.net.other[e.key] = e.value;
      }
      if (model.net.width < 1 || model.net.height < 1 || model.net.channels < 1)
        r.fail(s.line, fmt::format("width, height, channels = {}, {}, {}: must be >= 1", model.net.width,
                                   model.net.height, model.net.channels));
      continue;
    }
    if (s.name == "net" || s.name == "network") r.fail(s.line, "a second [net] section");
    Layer l;
    l.cfg_line = s.line;
    const int index = static_cast<int>(model.layers.size());
    if (s.name == "convolutional" || s.name == "conv") {
      l.type = LayerType::kConvolutional;
      l.batch_normalize = r.get_int("batch_normalize", 0) != 0;
      l.filters = r.get_int("filters", 1);
      l.size = r.get_int("size", 1);
      l.stride = r.get_int("stride", 1);
      const int pad = r.get_int("pad", 0);
      l.padding = r.get_int("padding", 0);
      if (pad) l.padding = l.size / 2;
      l.activation = parse_activation(r);
      if (l.filters < 1) r.fail(r.line_of("filters"), fmt::format("key 'filters' = {}: must be >= 1", l.filters));
      if (l.size < 1) r.fail(r.line_of("size"), fmt::format("key 'size' = {}: must be >= 1", l.size));
      if (l.stride < 1) r.fail(r.line_of("stride"), fmt::format("key 'stride' = {}: must be >= 1", l.stride));
      if (l.padding < 0) r.fail(r.line_of("padding"), fmt::format("key 'padding' = {}: must be >= 0", l.padding));
    } else if (s.name == "maxpool" || s.name == "max") {
      l.type = LayerType::kMaxpool;
      l.pool_size = r.get_int("size", 2);
      l.pool_stride = r.get_int("stride", 2);
      l.pool_padding = r.get_int("padding", l.pool_size - 1);
      if (l.pool_size < 1) r.fail(r.line_of("size"), fmt::format("key 'size' = {}: must be >= 1", l.pool_size));
      if (l.pool_stride < 1) r.fail(r.line_of("stride"), fmt::format("key 'stride' = {}: must be >= 1", l.pool_stride));
      if (l.pool_padding < 0)
        r.fail(r.line_of("padding"), fmt::format("key 'padding' = {}: must be >= 0", l.pool_padding));
    } else if (s.name == "region") {
      l.type = LayerType::kRegion;
      l.anchors = r.get_floats("anchors");
      l.classes = r.get_int("classes", 20);
      l.num = r.get_int("num", 1);
      const int coords = r.get_int("coords", 4);
      if (coords != 4) r.fail(r.line_of("coords"), fmt::format("key 'coords' = {}: only 4 is supported", coords));
      r.get_int("softmax", 0);
      l.object_scale = r.get_float("object_scale", l.object_scale);
      l.noobject_scale = r.get_float("noobject_scale", l.noobject_scale);
      l.class_scale = r.get_float("class_scale", l.class_scale);
      l.coord_scale = r.get_float("coord_scale", l.coord_scale);
      l.rescore = r.get_int("rescore", l.rescore);
      l.bias_match = r.get_int("bias_match", l.bias_match);
      l.absolute = r.get_int("absolute", l.absolute);
      l.thresh = r.get_float("thresh", l.thresh);
      l.jitter = r.get_float("jitter", l.jitter);
      l.random = r.get_float("random", l.random);
      if (l.num < 1) r.fail(r.line_of("num"), fmt::format("key 'num' = {}: must be >= 1", l.num));
      if (l.anchors.size() != static_cast<size_t>(2 * l.num))
        r.fail(r.line_of("anchors"), fmt::format("key 'anchors': expected {} values (2 x num = {}), got {}", 2 * l.num,
                                                 l.num, l.anchors.size()));
    } else if (s.name == "yolo") {
      l.type = LayerType::kYolo;
      l.anchors = r.get_floats("anchors");
      l.mask = r.get_ints("mask");
      l.classes = r.get_int("classes", 20);
      const int total = r.get_int("num", static_cast<int>(l.anchors.size() / 2));
      l.scale_x_y = r.get_float("scale_x_y", l.scale_x_y);
      l.ignore_thresh = r.get_float("ignore_thresh", l.ignore_thresh);
      l.truth_thresh = r.get_float("truth_thresh", l.truth_thresh);
      l.jitter = r.get_float("jitter", l.jitter);
      l.random = r.get_float("random", l.random);
      l.iou_loss = r.get_string("iou_loss", l.iou_loss);
      l.iou_normalizer = r.get_float("iou_normalizer", l.iou_normalizer);
      if (l.iou_loss != "mse" && l.iou_loss != "giou" && l.iou_loss != "diou" && l.iou_loss != "ciou")
        r.fail(r.line_of("iou_loss"),
               fmt::format("key 'iou_loss' = '{}': expected mse, giou, diou or ciou", l.iou_loss));
      if (!(l.iou_normalizer > 0.0f))
        r.fail(r.line_of("iou_normalizer"), fmt::format("key 'iou_normalizer' = {}: must be > 0", l.iou_normalizer));
      if (!(l.scale_x_y >= 1.0f))
        r.fail(r.line_of("scale_x_y"), fmt::format("key 'scale_x_y' = {}: must be >= 1", l.scale_x_y));
      if (l.anchors.size() != static_cast<size_t>(2 * total))
        r.fail(r.line_of("anchors"), fmt::format("key 'anchors': expected {} values (2 x num = {}), got {}", 2 * total,
                                                 total, l.anchors.size()));
      if (l.mask.empty())
        for (int i = 0; i < total; ++i) l.mask.push_back(i);
      for (int m : l.mask)
        if (m < 0 || m >= total)
          r.fail(r.line_of("mask"), fmt::format("key 'mask': index {} is outside 0..{}", m, total - 1));
      l.num = static_cast<int>(l.mask.size());
    } else if (s.name == "route") {
      l.type = LayerType::kRoute;
      const std::vector<int> rel = r.get_ints("layers");
      if (rel.empty()) r.fail(s.line, "key 'layers' is missing");
      for (int v : rel) {
        const int abs_index = v < 0 ? index + v : v;
        if (abs_index < 0 || abs_index >= index)
          r.fail(r.line_of("layers"),
                 fmt::format("key 'layers': {} refers to layer {}, expected 0..{}", v, abs_index, index - 1));
        l.route_layers.push_back(abs_index);
      }
    } else if (s.name == "upsample") {
      l.type = LayerType::kUpsample;
      l.upsample_stride = r.get_int("stride", 2);
      if (l.upsample_stride < 1)
        r.fail(r.line_of("stride"), fmt::format("key 'stride' = {}: must be >= 1", l.upsample_stride));
    } else {
      r.fail(s.line, "unsupported section (supported: net, convolutional, maxpool, region, route, upsample, yolo)");
    }
    r.check_all_used();
    model.layers.push_back(std::move(l));
  }
  compute_shapes(model);
  return model;
}

DarknetModel parse_darknet_cfg(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DarknetFormatError(fmt::format("{}: cannot open the .cfg file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_darknet_cfg_string(ss.str(), path);
}

namespace {

/// Largest layer output accepted, values (c x h x w), and largest convolution, weights: beyond them the int shapes
/// and counts would overflow (a fuzzed .cfg found it), and no network that runs here comes near.
constexpr int64_t kMaxLayerValues = (int64_t{1} << 31) - 1;
constexpr int64_t kMaxLayerWeights = (int64_t{1} << 31) - 1;
/// Largest network accepted, over all layers: output values (the activations a backend allocates, float32) and
/// weights. 2^28 values = 1 GiB each; the shipped 640x352 network has about 1.3 x 10^7 output values and 6.7 x 10^5
/// weights. A 1 KB .cfg must not make a process allocate many GB (issue 33, finding 5).
constexpr int64_t kMaxNetworkValues = int64_t{1} << 28;
constexpr int64_t kMaxNetworkWeights = int64_t{1} << 28;

}  // namespace

void compute_shapes(DarknetModel& model) {
  Shape current{model.net.channels, model.net.height, model.net.width};
  int64_t total_values = 0, total_weights = 0;
  for (size_t i = 0; i < model.layers.size(); ++i) {
    Layer& l = model.layers[i];
    // Computed in 64 bits and checked before they become the layer's int shape.
    int64_t c = 0;
    int64_t h = 0;
    int64_t w = 0;
    switch (l.type) {
      case LayerType::kConvolutional: {
        l.input = current;
        c = l.filters;
        h = (int64_t{l.input.h} + 2 * int64_t{l.padding} - l.size) / l.stride + 1;
        w = (int64_t{l.input.w} + 2 * int64_t{l.padding} - l.size) / l.stride + 1;
        const double weights = static_cast<double>(l.filters) * l.input.c * l.size * l.size;
        if (weights > static_cast<double>(kMaxLayerWeights))
          shape_error(model, l, i,
                      fmt::format("{} filters x {} channels x {}x{} = {:.0f} weights: more than {}", l.filters,
                                  l.input.c, l.size, l.size, weights, kMaxLayerWeights));
        break;
      }
      case LayerType::kMaxpool: {
        l.input = current;
        c = l.input.c;
        h = (int64_t{l.input.h} + l.pool_padding - l.pool_size) / l.pool_stride + 1;
        w = (int64_t{l.input.w} + l.pool_padding - l.pool_size) / l.pool_stride + 1;
        break;
      }
      case LayerType::kRegion:
      case LayerType::kYolo: {
        l.input = current;
        c = current.c;
        h = current.h;
        w = current.w;
        const int64_t expected = int64_t{l.num} * (5 + int64_t{l.classes});
        if (l.input.c != expected)
          shape_error(model, l, i,
                      fmt::format("input has {} channels, expected num x (5 + classes) = {} x (5 + {}) = {}", l.input.c,
                                  l.num, l.classes, expected));
        break;
      }
      case LayerType::kRoute: {
        for (int src : l.route_layers) {
          if (src < 0 || static_cast<size_t>(src) >= i)
            shape_error(model, l, i, fmt::format("route source {} is not an earlier layer", src));
          const Shape& s = model.layers[src].output;
          if (c == 0) {
            c = s.c;
            h = s.h;
            w = s.w;
          } else {
            if (s.h != h || s.w != w)
              shape_error(model, l, i,
                          fmt::format("layer {} is {}x{}, expected {}x{} like the first source", src, s.h, s.w, h, w));
            c += s.c;
            if (c > kMaxLayerValues) break;  // reported below
          }
        }
        l.input = {0, 0, 0};
        break;
      }
      case LayerType::kUpsample:
        l.input = current;
        c = current.c;
        h = int64_t{current.h} * l.upsample_stride;
        w = int64_t{current.w} * l.upsample_stride;
        break;
    }
    if (c < 1 || h < 1 || w < 1)
      shape_error(
          model, l, i,
          fmt::format("output shape {}x{}x{} from input {}x{}x{} is empty", c, h, w, l.input.c, l.input.h, l.input.w));
    if (static_cast<double>(c) * static_cast<double>(h) * static_cast<double>(w) > static_cast<double>(kMaxLayerValues))
      shape_error(model, l, i, fmt::format("output shape {}x{}x{}: more than {} values", c, h, w, kMaxLayerValues));
    l.output = {static_cast<int>(c), static_cast<int>(h), static_cast<int>(w)};
    if (l.type == LayerType::kRoute) l.input = l.output;
    current = l.output;
    total_values += l.output.size();
    if (l.type == LayerType::kConvolutional)
      total_weights += int64_t{l.filters} * l.input.c * l.size * l.size + int64_t{l.filters} * 4;
    if (total_values > kMaxNetworkValues)
      shape_error(model, l, i,
                  fmt::format("the layers up to this one output {} values in all: more than {} (1 GiB of float32; "
                              "network input {}x{}x{})",
                              total_values, kMaxNetworkValues, model.net.width, model.net.height, model.net.channels));
    if (total_weights > kMaxNetworkWeights)
      shape_error(model, l, i,
                  fmt::format("the layers up to this one hold {} weights in all: more than {} (1 GiB of float32)",
                              total_weights, kMaxNetworkWeights));
  }
}

std::string write_darknet_cfg(const DarknetModel& model) {
  std::string s = "[net]\n";
  s += fmt::format("width={}\nheight={}\nchannels={}\n", model.net.width, model.net.height, model.net.channels);
  for (const auto& [key, value] : model.net.other) s += fmt::format("{}={}\n", key, value);
  for (const Layer& l : model.layers) {
    s += fmt::format("\n[{}]\n", layer_type_name(l.type));
    switch (l.type) {
      case LayerType::kConvolutional:
        if (l.batch_normalize) s += "batch_normalize=1\n";
        s += fmt::format("filters={}\nsize={}\nstride={}\npadding={}\nactivation={}\n", l.filters, l.size, l.stride,
                         l.padding, activation_name(l.activation));
        break;
      case LayerType::kMaxpool:
        s += fmt::format("size={}\nstride={}\npadding={}\n", l.pool_size, l.pool_stride, l.pool_padding);
        break;
      case LayerType::kRegion:
        s += fmt::format("anchors={}\nclasses={}\ncoords=4\nnum={}\nsoftmax=1\n", join_floats(l.anchors), l.classes,
                         l.num);
        s += fmt::format(
            "object_scale={}\nnoobject_scale={}\nclass_scale={}\ncoord_scale={}\nrescore={}\nbias_match={}\n"
            "absolute={}\nthresh={}\njitter={}\nrandom={}\n",
            l.object_scale, l.noobject_scale, l.class_scale, l.coord_scale, l.rescore, l.bias_match, l.absolute,
            l.thresh, l.jitter, l.random);
        break;
      case LayerType::kYolo:
        s += fmt::format("mask={}\nanchors={}\nclasses={}\nnum={}\n", join_ints(l.mask), join_floats(l.anchors),
                         l.classes, l.anchors.size() / 2);
        if (l.scale_x_y != 1.0f) s += fmt::format("scale_x_y={}\n", l.scale_x_y);  // not a key of every Darknet
        s += fmt::format("ignore_thresh={}\ntruth_thresh={}\njitter={}\nrandom={}\n", l.ignore_thresh, l.truth_thresh,
                         l.jitter, l.random);
        if (l.iou_loss != "mse") s += fmt::format("iou_loss={}\niou_normalizer={}\n", l.iou_loss, l.iou_normalizer);
        break;
      case LayerType::kRoute:
        s += fmt::format("layers={}\n", join_ints(l.route_layers));
        break;
      case LayerType::kUpsample:
        s += fmt::format("stride={}\n", l.upsample_stride);
        break;
    }
  }
  return s;
}

int64_t DarknetModel::weight_count() const {
  int64_t n = 0;
  for (const Layer& l : layers) {
    if (l.type != LayerType::kConvolutional) continue;
    n += l.filters * (l.batch_normalize ? 4 : 1);
    n += static_cast<int64_t>(l.filters) * l.input.c * l.size * l.size;
  }
  return n;
}

std::vector<int> DarknetModel::heads() const {
  std::vector<int> h;
  for (size_t i = 0; i < layers.size(); ++i)
    if (layers[i].type == LayerType::kRegion || layers[i].type == LayerType::kYolo) h.push_back(static_cast<int>(i));
  return h;
}

double DarknetModel::flops() const {
  double f = 0.0;
  for (const Layer& l : layers) {
    if (l.type != LayerType::kConvolutional) continue;
    // Darknet: 2 * n * size * size * c * out_h * out_w (a multiply-add is two FLOP).
    f += 2.0 * l.filters * l.size * l.size * l.input.c * static_cast<double>(l.output.h) * l.output.w;
  }
  return f;
}

}  // namespace wingman::detector
