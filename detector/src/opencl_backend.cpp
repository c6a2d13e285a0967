// SPDX-License-Identifier: MIT
// OpenClBackend: plans buffers and kernels for a DarknetModel once, then forward() only enqueues.
#include "wingman/detector/opencl_backend.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "opencl_runtime.hpp"

namespace wingman::detector {
namespace {

constexpr int kBlock = 16;                  // channels per block (one float16)
constexpr size_t kSlackFloats = 64 * 16;    // read-only overrun of the last tile of a buffer
constexpr float kBatchNormEpsilon = 1e-6f;  // as OpenCV's Darknet importer: gamma / sqrt(var + eps)

int blocks(int channels) { return (channels + kBlock - 1) / kBlock; }

/// A tensor of max_batch images in the blocked layout [N][C/16][H+2B][W+2B][16], or (planar, only the
/// network input when the first layer is a convolution) [N][C][H+2B][W+2B].
struct Tensor {
  Shape shape;
  int cb = 0, hp = 0, wp = 0, border = 0;
  bool planar = false;
  size_t image_floats() const {
    return planar ? static_cast<size_t>(shape.c) * hp * wp : static_cast<size_t>(cb) * hp * wp * kBlock;
  }
  cl::Buffer buffer;
};

/// One kernel launch; dimension `batch_dim` of the global size is per image and scales with the batch.
struct Step {
  cl::Kernel kernel;
  size_t global[3] = {1, 1, 1};
  int dims = 2;
  int batch_dim = 1;
  std::string what;  // for error messages and the profile
  int layer = -1;    // model layer index, -1 for layout steps
  double flops = 0;  // per image
};

std::string layer_name(const Layer& l, size_t index) {
  static const char* names[] = {"convolutional", "maxpool", "region", "route", "upsample", "yolo"};
  std::ostringstream s;
  s << "layer " << index << " [" << names[static_cast<int>(l.type)] << "] (cfg line " << l.cfg_line << ")";
  return s.str();
}

/// Tile width for an output width `w`, with `kbw` output blocks per work-item (even for a fused pooling):
/// of 8..13 (KBW x TW <= 26 accumulators; wider tiles spill registers, docs/pocl-performance.md) the one
/// with the highest (FMAs per load: TW KBW / (TW + KBW), broadcast inputs plus weight vectors) x (share of
/// computed columns that are real: w / (tiles x TW)); ties go to the wider tile. A model, not a
/// measurement: e.g. 13 for 13, 26, 52, ..., 416; 12 for an even 416 or 208; 10 for an even 26.
int tile_width(int w, int kbw, bool even) {
  int best = 8;
  double best_score = -1;
  for (int t = 13; t >= 8; --t) {
    if (even && t % 2 != 0) continue;
    const int tiles = (w + t - 1) / t;
    const double score = static_cast<double>(t) * kbw / (t + kbw) * w / (static_cast<double>(tiles) * t);
    if (score > best_score + 1e-9) {
      best = t;
      best_score = score;
    }
  }
  return best;
}

/// Folds batch normalisation into the weights and packs them as conv2d_blocked.cl reads them:
/// [K/kout][C/win][KS*KS][win in][kout out] (kout = 16 x output blocks per work-item; win = 16, or 1 for a
/// planar input), zero-padded; bias to a multiple of kout. Validates the weight array sizes.
void pack_convolution(const Layer& l, size_t index, int kout, int win, std::vector<float>& packed,
                      std::vector<float>& bias, std::vector<float>* folded = nullptr) {
  const int k_count = l.filters, c_count = l.input.c, kk = l.size * l.size;
  const size_t want = static_cast<size_t>(k_count) * c_count * kk;
  auto check = [&](const std::vector<float>& v, size_t n, const char* what) {
    if (v.size() != n)
      throw std::invalid_argument(layer_name(l, index) + ": " + what + " has " + std::to_string(v.size()) +
                                  " values, expected " + std::to_string(n) + " (weights not loaded?)");
  };
  check(l.weights, want, "weights");
  check(l.biases, static_cast<size_t>(k_count), "biases");
  const int kg_count = (k_count + kout - 1) / kout, cb_count = (c_count + win - 1) / win;
  std::vector<float> scale(k_count, 1.0f);
  bias.assign(static_cast<size_t>(kg_count) * kout, 0.0f);
  if (l.batch_normalize) {
    check(l.scales, k_count, "scales");
    check(l.rolling_mean, k_count, "rolling_mean");
    check(l.rolling_variance, k_count, "rolling_variance");
    for (int k = 0; k < k_count; ++k) {
      scale[k] = l.scales[k] / std::sqrt(l.rolling_variance[k] + kBatchNormEpsilon);
      bias[k] = l.biases[k] - l.rolling_mean[k] * scale[k];
    }
  } else {
    for (int k = 0; k < k_count; ++k) bias[k] = l.biases[k];
  }
  packed.assign(static_cast<size_t>(kg_count) * cb_count * kk * win * kout, 0.0f);
  if (folded) folded->assign(want, 0.0f);
  for (int k = 0; k < k_count; ++k)
    for (int c = 0; c < c_count; ++c)
      for (int t = 0; t < kk; ++t) {
        const size_t dst =
            ((((static_cast<size_t>(k / kout) * cb_count + c / win) * kk + t) * win + c % win) * kout) + k % kout;
        const size_t src = (static_cast<size_t>(k) * c_count + c) * kk + t;
        packed[dst] = l.weights[src] * scale[k];
        if (folded) (*folded)[src] = packed[dst];
      }
}

/// Winograd F(2x2, 3x3) weights of a 3x3 convolution (batch normalisation folded in): U = G g G^T per
/// output and input channel, G = [1 0 0; 1/2 1/2 1/2; 1/2 -1/2 1/2; 0 0 1], packed as the 1x1
/// convolutions of winograd_blocked.cl read them: [16 xi][K/kout][C/16][1][16 in][kout out]. `folded_3x3`:
/// the weights with batch normalisation folded in, OIHW (pack_convolution's `folded`).
std::vector<float> pack_winograd(const Layer& l, const std::vector<float>& folded_3x3, int kout) {
  const int k_count = l.filters, c_count = l.input.c;
  const int kg_count = (k_count + kout - 1) / kout, cb_count = blocks(c_count);
  const double g_rows[4][3] = {{1, 0, 0}, {0.5, 0.5, 0.5}, {0.5, -0.5, 0.5}, {0, 0, 1}};
  std::vector<float> packed(static_cast<size_t>(16) * kg_count * cb_count * kBlock * kout, 0.0f);
  for (int k = 0; k < k_count; ++k)
    for (int c = 0; c < c_count; ++c) {
      const float* g = folded_3x3.data() + (static_cast<size_t>(k) * c_count + c) * 9;
      double gg[4][3];  // G g
      for (int r = 0; r < 4; ++r)
        for (int j = 0; j < 3; ++j) gg[r][j] = g_rows[r][0] * g[j] + g_rows[r][1] * g[3 + j] + g_rows[r][2] * g[6 + j];
      for (int r = 0; r < 4; ++r)
        for (int q = 0; q < 4; ++q) {
          const double u = gg[r][0] * g_rows[q][0] + gg[r][1] * g_rows[q][1] + gg[r][2] * g_rows[q][2];  // (G g G^T)
          const size_t xi = static_cast<size_t>(4 * r + q);
          const size_t dst =
              ((((xi * kg_count + k / kout) * cb_count + c / kBlock) * kBlock + c % kBlock) * kout) + k % kout;
          packed[dst] = static_cast<float>(u);
        }
    }
  return packed;
}

/// Whether convolution `l` runs as Winograd F(2x2, 3x3): 3x3, stride 1, padding 1, a blocked input, no
/// fused pooling, and at least kWinogradMinChannels input channels. 256 is the smallest depth measured
/// (the thesis network's layer 10, 256 -> 512 at 13 x 13: faster as Winograd, transforms included;
/// docs/benchmarks.md); shallower 3x3 layers of that network are pooling-fused and were not compared.
constexpr int kWinogradMinChannels = 256;
bool use_winograd(const Layer& l, bool planar_input, bool pooled) {
  return l.size == 3 && l.stride == 1 && l.padding == 1 && !planar_input && !pooled &&
         l.input.c >= kWinogradMinChannels;
}

int activation_code(Activation a) {
  switch (a) {
    case Activation::kLinear:
      return 0;
    case Activation::kLeaky:
      return 1;
    case Activation::kLogistic:
      return 2;
  }
  return 0;
}

}  // namespace

struct OpenClBackend::Impl {
  OpenClOptions options;
  cl::Device device;
  cl::Context context;
  cl::CommandQueue queue;
  cl::Program misc_program;
  std::map<std::string, cl::Program> conv_programs;  // by their -D options
  std::vector<Tensor> tensors;                       // 0: network input
  std::vector<cl::Buffer> constants;                 // packed weights and biases, kept alive
  std::vector<Step> steps;
  Shape input_shape;
  std::vector<Shape> output_shapes;    // per image, in order
  std::vector<int> output_tensors;     // the tensors behind output_shapes
  cl::Buffer staging_in, staging_out;  // plain N x C x H x W
  cl::Buffer winograd_v, winograd_m;   // Winograd scratch shared by the layers (in-order queue)
  Step pack;
  std::vector<Step> unpacks;  // one per output tensor

  cl::Program build(const std::string& source, const std::string& defines) {
    cl::Program program(context, source);
    const std::string opts = "-cl-std=CL1.2 " + options.build_options + " " + defines;
    try {
      program.build({device}, opts.c_str());
    } catch (const cl::Error& e) {
      std::string log;
      try {
        log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device);
      } catch (const cl::Error&) {
      }
      // One line (fatal errors are one line): the log's lines joined, cut to a readable length.
      std::string one_line;
      for (char c : log) {
        if (c == '\n' || c == '\r') {
          if (!one_line.empty() && one_line.back() != ' ') one_line += " | ";
        } else {
          one_line += c;
        }
      }
      while (!one_line.empty() && (one_line.back() == ' ' || one_line.back() == '|')) one_line.pop_back();
      if (one_line.size() > 400) one_line = one_line.substr(0, 400) + " ...";
      throw std::runtime_error(describe_cl_error(e, "building OpenCL program with '" + opts + "'") +
                               (one_line.empty() ? std::string("; empty build log") : "; build log: " + one_line));
    }
    return program;
  }

  cl::Program& conv_program(int tw, int ks, int stride, int cin, int kbw, bool planar, bool pool) {
    std::ostringstream d;
    d << "-D TW=" << tw << " -D KS=" << ks << " -D STRIDE=" << stride << " -D CIN=" << cin << " -D KBW=" << kbw
      << " -D PLANAR=" << (planar ? 1 : 0) << " -D POOL=" << (pool ? 1 : 0);
    auto it = conv_programs.find(d.str());
    if (it == conv_programs.end())
      it = conv_programs.emplace(d.str(), build(opencl_sources::all().at("conv2d_blocked.cl"), d.str())).first;
    return it->second;
  }

  int add_tensor(const Shape& s, int border, bool planar = false) {
    Tensor t;
    t.shape = s;
    t.cb = blocks(s.c);
    t.border = border;
    t.planar = planar;
    t.hp = s.h + 2 * border;
    t.wp = s.w + 2 * border;
    const size_t floats = t.image_floats() * options.max_batch + kSlackFloats;
    // Zero-filled once: borders and unused channel lanes stay zero forever (kernels write interiors).
    std::vector<float> zeros(floats, 0.0f);
    t.buffer = cl::Buffer(context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, floats * sizeof(float), zeros.data());
    tensors.push_back(std::move(t));
    return static_cast<int>(tensors.size()) - 1;
  }

  cl::Buffer constant(const std::vector<float>& v) {
    std::vector<float> copy = v;
    copy.resize(v.size() + kSlackFloats, 0.0f);
    constants.emplace_back(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, copy.size() * sizeof(float), copy.data());
    return constants.back();
  }

  void plan(const DarknetModel& model) {
    if (model.layers.empty()) throw std::invalid_argument("OpenClBackend: the model has no layers");
    int border = 0;
    for (const auto& l : model.layers)
      if (l.type == LayerType::kConvolutional) border = std::max(border, l.padding);
    input_shape = Shape{model.net.channels, model.net.height, model.net.width};
    // A first convolution reads the input planar (C <= 16 planes), which the host writes straight into the
    // bordered buffer (enqueueWriteBufferRect); otherwise a kernel packs it into blocks.
    const Layer& first = model.layers.front();
    planar_input = first.type == LayerType::kConvolutional && input_shape.c <= kBlock && first.padding <= border;
    add_tensor(input_shape, border, planar_input);
    allocate_winograd_scratch(model);
    std::vector<int> layer_tensor(model.layers.size(), -1);
    std::vector<bool> routed(model.layers.size(), false);  // some [route] reads the layer's output
    for (const Layer& l : model.layers)
      for (const int r : l.route_layers)
        if (r >= 0 && static_cast<size_t>(r) < routed.size()) routed[r] = true;
    int current = 0;
    for (size_t i = 0; i < model.layers.size(); ++i) {
      const Layer& l = model.layers[i];
      const std::string name = layer_name(l, i);
      if (l.type != LayerType::kRoute && !(tensors[current].shape == l.input))
        throw std::invalid_argument(name + ": input shape does not follow the previous layer's output");
      switch (l.type) {
        case LayerType::kConvolutional: {
          // A following 2x2 stride-2 max-pooling (Darknet's padding: windows from the top-left) is fused
          // into the convolution unless something else reads the convolution's own output, or the even
          // tile width fusing needs computes more than 5 % of columns in vain (measured: fusing 52- and
          // 26-wide layers, 13 % waste, was slower than convolution + pooling; 416..104, <= 4 %, faster or
          // equal).
          const Layer* pool = nullptr;
          if (i + 1 < model.layers.size() && !routed[i] && l.stride == 1) {
            const Layer& p = model.layers[i + 1];
            const int tw = tile_width(l.output.w, blocks(l.filters) >= 2 ? 2 : 1, true);
            const int computed = (l.output.w + tw - 1) / tw * tw;
            if (p.type == LayerType::kMaxpool && p.pool_size == 2 && p.pool_stride == 2 && p.pool_padding == 1 &&
                p.input == l.output && computed <= 1.05 * l.output.w)
              pool = &p;
          }
          current = plan_convolution(l, i, current, border, pool);
          if (pool) {
            ++i;  // the pooling is done: its output is this tensor
            if (!(tensors[current].shape == pool->output))
              throw std::invalid_argument(layer_name(*pool, i) + ": computed output shape differs from the model's");
            layer_tensor[i] = current;
            continue;
          }
          break;
        }
        case LayerType::kMaxpool:
          current = plan_maxpool(l, i, current, border);
          break;
        case LayerType::kUpsample:
          current = plan_upsample(l, i, current, border);
          break;
        case LayerType::kRoute:
          current = plan_route(l, i, layer_tensor, border);
          break;
        case LayerType::kRegion:
        case LayerType::kYolo:
          break;  // decoded on the host from the previous layer's output
      }
      if (!(tensors[current].shape == l.output))
        throw std::invalid_argument(name + ": computed output shape differs from the model's");
      layer_tensor[i] = current;
      if (l.type == LayerType::kRegion || l.type == LayerType::kYolo) output_tensors.push_back(current);
    }
    if (output_tensors.empty()) output_tensors.push_back(current);  // no heads: the last layer's output
    for (const int t : output_tensors) output_shapes.push_back(tensors[t].shape);

    const int64_t out_image = output_size(output_shapes);
    staging_out = cl::Buffer(context, CL_MEM_WRITE_ONLY, out_image * options.max_batch * sizeof(float));
    if (!planar_input) {
      staging_in = cl::Buffer(context, CL_MEM_READ_ONLY, input_shape.size() * options.max_batch * sizeof(float));
      pack = layout_step("pack_nchw_to_blocked", tensors[0]);
      pack.kernel.setArg(0, staging_in);
      pack.kernel.setArg(1, tensors[0].buffer);
    }
    int64_t offset = 0;
    for (const int t : output_tensors) {
      Step u = layout_step("unpack_blocked_to_nchw", tensors[t]);
      u.kernel.setArg(0, tensors[t].buffer);
      u.kernel.setArg(1, staging_out);
      u.kernel.setArg(9, static_cast<cl_long>(out_image));
      u.kernel.setArg(10, static_cast<cl_long>(offset));
      offset += tensors[t].shape.size();
      unpacks.push_back(std::move(u));
    }
  }

  /// A layout kernel over tensor `t`, one work-item per row and channel; arguments 0 and 1 (the buffers)
  /// are the caller's.
  Step layout_step(const char* kernel_name, const Tensor& t) {
    Step s;
    s.what = kernel_name;
    s.kernel = cl::Kernel(misc_program, kernel_name);
    const int args[] = {t.shape.c, t.cb, t.shape.h, t.shape.w, t.hp, t.wp, t.border};
    for (int a = 0; a < 7; ++a) s.kernel.setArg(2 + a, args[a]);
    s.global[0] = t.shape.h;
    s.global[1] = t.shape.c;
    return s;
  }

  /// Tiles of the Winograd "image" of a layer with output w x h, and its width padded to the 1x1
  /// convolution's tile width (v_w).
  struct WinogradGeometry {
    int tiles_w = 0, tiles_h = 0, tiles = 0, tw = 0, v_w = 0, kbw = 1;
  };
  static WinogradGeometry winograd_geometry(const Layer& l) {
    WinogradGeometry g;
    g.tiles_w = (l.output.w + 1) / 2;
    g.tiles_h = (l.output.h + 1) / 2;
    g.tiles = g.tiles_w * g.tiles_h;
    g.kbw = blocks(l.filters) >= 2 ? 2 : 1;
    g.tw = tile_width(g.tiles, g.kbw, false);
    g.v_w = (g.tiles + g.tw - 1) / g.tw * g.tw;
    return g;
  }

  /// Scratch for V and M of the largest Winograd layer, max_batch images.
  void allocate_winograd_scratch(const DarknetModel& model) {
    size_t v = 0, m = 0;
    for (size_t i = 0; i < model.layers.size(); ++i) {
      const Layer& l = model.layers[i];
      if (l.type != LayerType::kConvolutional || !use_winograd(l, i == 0 && planar_input, false)) continue;
      const WinogradGeometry g = winograd_geometry(l);
      v = std::max(v, static_cast<size_t>(16) * blocks(l.input.c) * g.v_w * kBlock);
      m = std::max(m, static_cast<size_t>(16) * blocks(l.filters) * g.v_w * kBlock);
    }
    if (v == 0) return;
    // Zero-filled: the tile columns past the last tile are read by the 1x1 convolution but never written.
    std::vector<float> zeros(std::max(v, m) * options.max_batch + kSlackFloats, 0.0f);
    winograd_v = cl::Buffer(context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                            (v * options.max_batch + kSlackFloats) * sizeof(float), zeros.data());
    winograd_m = cl::Buffer(context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                            (m * options.max_batch + kSlackFloats) * sizeof(float), zeros.data());
  }

  /// Plans 3x3 convolution `l` as Winograd F(2x2, 3x3): input transform, 16 1x1 convolutions, output
  /// transform with bias and activation (winograd_blocked.cl).
  int plan_winograd(const Layer& l, size_t index, int in, int border) {
    const WinogradGeometry g = winograd_geometry(l);
    const int kout = g.kbw * kBlock;
    std::vector<float> packed_3x3, bias, folded;
    pack_convolution(l, index, kout, kBlock, packed_3x3, bias, &folded);
    const std::vector<float> u = pack_winograd(l, folded, kout);
    const int out = add_tensor(l.output, border);
    const Tensor& ti = tensors[in];
    const Tensor& to = tensors[out];
    const std::string name = layer_name(l, index);
    const double flops = 2.0 * l.filters * 9 * l.input.c * static_cast<double>(l.output.h) * l.output.w;

    Step input;
    input.what = name + " winograd: input transform";
    input.layer = static_cast<int>(index);
    input.kernel = cl::Kernel(misc_program, "winograd_input");
    input.kernel.setArg(0, ti.buffer);
    input.kernel.setArg(1, winograd_v);
    const int in_args[] = {ti.cb, ti.hp, ti.wp, ti.border, g.tiles_w, g.v_w};
    for (int a = 0; a < 6; ++a) input.kernel.setArg(2 + a, in_args[a]);
    input.global[0] = g.tiles_w;
    input.global[1] = g.tiles_h;
    input.global[2] = ti.cb;
    input.dims = 3;
    input.batch_dim = 2;
    steps.push_back(std::move(input));

    Step products;
    products.what = name + " winograd: 16 products (GFLOP/s: the direct convolution's FLOP)";
    products.layer = static_cast<int>(index);
    products.flops = flops;
    const int cin = ti.cb == 1 ? ti.shape.c : kBlock;
    products.kernel = cl::Kernel(conv_program(g.tw, 1, 1, cin, g.kbw, false, false), "conv2d_blocked");
    products.kernel.setArg(0, winograd_v);
    products.kernel.setArg(1, constant(u));
    products.kernel.setArg(2, constant(std::vector<float>(bias.size(), 0.0f)));  // the output transform adds it
    products.kernel.setArg(3, winograd_m);
    const int p_args[] = {ti.cb, 1, g.v_w, 0, to.cb, 1, g.tiles, 1, g.v_w, 0, activation_code(Activation::kLinear), 16};
    for (int a = 0; a < 12; ++a) products.kernel.setArg(4 + a, p_args[a]);
    products.global[0] = g.v_w / g.tw;
    products.global[1] = 1;
    products.global[2] = static_cast<size_t>((to.cb + g.kbw - 1) / g.kbw) * 16;
    products.dims = 3;
    products.batch_dim = 2;
    steps.push_back(std::move(products));

    Step output;
    output.what = name + " winograd: output transform";
    output.layer = static_cast<int>(index);
    output.kernel = cl::Kernel(misc_program, "winograd_output");
    output.kernel.setArg(0, winograd_m);
    output.kernel.setArg(1, constant(bias));
    output.kernel.setArg(2, to.buffer);
    const int out_args[] = {
        to.cb, g.tiles_w, g.v_w, to.shape.h, to.shape.w, to.hp, to.wp, to.border, activation_code(l.activation)};
    for (int a = 0; a < 9; ++a) output.kernel.setArg(3 + a, out_args[a]);
    output.global[0] = g.tiles_w;
    output.global[1] = g.tiles_h;
    output.global[2] = to.cb;
    output.dims = 3;
    output.batch_dim = 2;
    steps.push_back(std::move(output));
    return out;
  }

  /// Plans convolution `l`, and when `pool` is not null the 2x2 stride-2 max-pooling after it (fused).
  int plan_convolution(const Layer& l, size_t index, int in, int border, const Layer* pool) {
    if (l.size < 1 || l.stride < 1 || l.padding < 0 || l.padding > border)
      throw std::invalid_argument(layer_name(l, index) + ": unsupported size/stride/padding");
    const bool planar = tensors[in].planar;
    if (use_winograd(l, planar, pool != nullptr)) return plan_winograd(l, index, in, border);
    // Two output blocks per work-item where there are two: each broadcast input then feeds two FMAs.
    const int kbw = blocks(l.filters) >= 2 ? 2 : 1;
    std::vector<float> packed, bias;
    pack_convolution(l, index, kbw * kBlock, planar ? 1 : kBlock, packed, bias);
    const int out = add_tensor(pool ? pool->output : l.output, border);
    const Tensor& ti = tensors[in];  // after add_tensor, which may move the tensors
    const Tensor& to = tensors[out];
    const int tw = tile_width(l.output.w, kbw, pool != nullptr);
    const int cin = planar ? 1 : ti.cb == 1 ? ti.shape.c : kBlock;
    const int in_blocks = planar ? ti.shape.c : ti.cb;
    const int tiles = (l.output.w + tw - 1) / tw;
    Step s;
    s.what = layer_name(l, index) + (pool ? " + " + layer_name(*pool, index + 1) + " fused" : "");
    s.layer = static_cast<int>(index);
    s.flops = 2.0 * l.filters * l.size * l.size * l.input.c * static_cast<double>(l.output.h) * l.output.w;
    s.kernel = cl::Kernel(conv_program(tw, l.size, l.stride, cin, kbw, planar, pool != nullptr), "conv2d_blocked");
    s.kernel.setArg(0, ti.buffer);
    s.kernel.setArg(1, constant(packed));
    s.kernel.setArg(2, constant(bias));
    s.kernel.setArg(3, to.buffer);
    const int args[] = {in_blocks, ti.hp, ti.wp,     ti.border - l.padding,        to.cb, l.output.h, l.output.w,
                        to.hp,     to.wp, to.border, activation_code(l.activation)};
    for (int a = 0; a < 11; ++a) s.kernel.setArg(4 + a, args[a]);
    s.kernel.setArg(15, 1);  // w_groups: one weight set
    s.global[0] = tiles;
    s.global[1] = to.shape.h;
    s.global[2] = (to.cb + kbw - 1) / kbw;
    s.dims = 3;
    s.batch_dim = 2;
    steps.push_back(std::move(s));
    return out;
  }

  int plan_maxpool(const Layer& l, size_t index, int in, int border) {
    if (l.pool_size < 1 || l.pool_stride < 1 || l.pool_padding < 0)
      throw std::invalid_argument(layer_name(l, index) + ": unsupported pool size/stride/padding");
    const int out = add_tensor(l.output, border);
    const Tensor& ti = tensors[in];
    const Tensor& to = tensors[out];
    Step s;
    s.what = layer_name(l, index);
    s.layer = static_cast<int>(index);
    s.kernel = cl::Kernel(misc_program, "maxpool_blocked");
    s.kernel.setArg(0, ti.buffer);
    s.kernel.setArg(1, to.buffer);
    const int args[] = {ti.cb, ti.shape.h, ti.shape.w, ti.hp,       ti.wp,         ti.border,         to.shape.w,
                        to.hp, to.wp,      to.border,  l.pool_size, l.pool_stride, l.pool_padding / 2};
    for (int a = 0; a < 13; ++a) s.kernel.setArg(2 + a, args[a]);
    s.global[0] = to.shape.h;
    s.global[1] = to.cb;
    steps.push_back(std::move(s));
    return out;
  }

  int plan_upsample(const Layer& l, size_t index, int in, int border) {
    if (l.upsample_stride < 1) throw std::invalid_argument(layer_name(l, index) + ": unsupported upsample stride");
    const int out = add_tensor(l.output, border);
    const Tensor& ti = tensors[in];
    const Tensor& to = tensors[out];
    Step s;
    s.what = layer_name(l, index);
    s.layer = static_cast<int>(index);
    s.kernel = cl::Kernel(misc_program, "upsample_blocked");
    s.kernel.setArg(0, ti.buffer);
    s.kernel.setArg(1, to.buffer);
    const int args[] = {ti.hp, ti.wp, ti.border, to.shape.w, to.hp, to.wp, to.border, l.upsample_stride};
    for (int a = 0; a < 8; ++a) s.kernel.setArg(2 + a, args[a]);
    s.global[0] = to.shape.h;
    s.global[1] = to.cb;
    steps.push_back(std::move(s));
    return out;
  }

  int plan_route(const Layer& l, size_t index, const std::vector<int>& layer_tensor, int border) {
    if (l.route_layers.empty()) throw std::invalid_argument(layer_name(l, index) + ": route without layers");
    const int out = add_tensor(l.output, border);
    int offset = 0;
    for (int r : l.route_layers) {
      if (r < 0 || r >= static_cast<int>(index))
        throw std::invalid_argument(layer_name(l, index) + ": route to layer " + std::to_string(r) +
                                    " which is not before it");
      const Tensor& ti = tensors[layer_tensor[r]];
      const Tensor& to = tensors[out];
      if (ti.shape.h != to.shape.h || ti.shape.w != to.shape.w || offset + ti.shape.c > to.shape.c)
        throw std::invalid_argument(layer_name(l, index) + ": routed layer " + std::to_string(r) +
                                    " does not fit the output shape");
      // Both tensors share the output's border and padded size (h, w equal; add_tensor pads alike).
      if (ti.hp != to.hp || ti.wp != to.wp || ti.border != to.border)
        throw std::logic_error(layer_name(l, index) + ": routed layer " + std::to_string(r) +
                               " has another padding than the output");
      // Whole blocks (both counts multiples of 16): one 16-float vector per pixel; else channel by channel.
      const bool blocks = offset % 16 == 0 && ti.shape.c % 16 == 0;
      Step s;
      s.what = layer_name(l, index) + (blocks ? " copy: whole blocks" : " copy: channel by channel");
      s.layer = static_cast<int>(index);
      s.kernel = cl::Kernel(misc_program, blocks ? "route_copy_blocks" : "route_copy_blocked");
      s.kernel.setArg(0, ti.buffer);
      s.kernel.setArg(1, to.buffer);
      const int args[] = {blocks ? ti.shape.c / 16 : ti.shape.c,
                          ti.cb,
                          to.cb,
                          blocks ? offset / 16 : offset,
                          to.shape.h,
                          to.shape.w,
                          to.hp,
                          to.wp,
                          to.border};
      for (int a = 0; a < 9; ++a) s.kernel.setArg(2 + a, args[a]);
      s.global[0] = to.shape.h;
      s.global[1] = blocks ? ti.shape.c / 16 : ti.shape.c;
      steps.push_back(std::move(s));
      offset += ti.shape.c;
    }
    if (offset != tensors[out].shape.c)
      throw std::invalid_argument(layer_name(l, index) + ": routed channels do not add up to the output's");
    return out;
  }

  /// Enqueues `s` for `batch` images; with profiling, keeps its event as `slot` of the profile.
  void enqueue(const Step& s, int batch, size_t slot) {
    size_t g[3] = {s.global[0], s.global[1], s.global[2]};
    g[s.batch_dim] *= static_cast<size_t>(batch);
    const cl::NDRange global = s.dims == 3 ? cl::NDRange(g[0], g[1], g[2]) : cl::NDRange(g[0], g[1]);
    const cl::NDRange local = s.dims == 3 ? cl::NDRange(1, 1, 1) : cl::NDRange(1, 1);
    queue.enqueueNDRangeKernel(s.kernel, cl::NullRange, global, local, nullptr, profiling ? &events[slot] : nullptr);
  }

  /// Writes `batch` CHW images into the network input: straight into the bordered planar tensor, or
  /// through the staging buffer and the pack kernel.
  void write_input(const float* input, int batch) {
    const Tensor& t = tensors[0];
    cl::Event* e = profiling ? &events[0] : nullptr;
    if (t.planar) {
      const std::array<cl::size_type, 3> buffer_origin{static_cast<size_t>(t.border) * sizeof(float),
                                                       static_cast<size_t>(t.border), 0};
      const std::array<cl::size_type, 3> host_origin{0, 0, 0};
      const std::array<cl::size_type, 3> region{static_cast<size_t>(t.shape.w) * sizeof(float),
                                                static_cast<size_t>(t.shape.h), static_cast<size_t>(t.shape.c) * batch};
      queue.enqueueWriteBufferRect(t.buffer, CL_FALSE, buffer_origin, host_origin, region, t.wp * sizeof(float),
                                   static_cast<size_t>(t.wp) * t.hp * sizeof(float), t.shape.w * sizeof(float),
                                   static_cast<size_t>(t.shape.w) * t.shape.h * sizeof(float), input, nullptr, e);
    } else {
      queue.enqueueWriteBuffer(staging_in, CL_FALSE, 0, input_shape.size() * batch * sizeof(float), input, nullptr, e);
      enqueue(pack, batch, 1);
    }
  }

  bool planar_input = false;
  bool profiling = false;
  // Profiling: one event per slot of the forward (input write, pack, steps..., unpack, output read) and
  // the device milliseconds of every profiled forward per slot.
  std::vector<cl::Event> events;
  std::vector<KernelTiming> timings;

  void start_profiling() {
    timings.clear();
    auto add = [&](const std::string& what, int layer, double flops) {
      KernelTiming k;
      k.what = what;
      k.layer = layer;
      k.flops = flops;
      timings.push_back(std::move(k));
    };
    add(planar_input ? "input: host to device (planar, bordered)" : "input: host to device (staging)", -1, 0);
    add(planar_input ? "input: (no pack kernel)" : "input: pack_nchw_to_blocked", -1, 0);
    for (const Step& s : steps) add(s.what, s.layer, s.flops);
    for (size_t i = 0; i < unpacks.size(); ++i) add("output " + std::to_string(i) + ": unpack_blocked_to_nchw", -1, 0);
    add("output: device to host", -1, 0);
    events.assign(timings.size(), cl::Event());
  }

  void record_profile(int batch) {
    for (size_t i = 0; i < events.size(); ++i) {
      if (!events[i]()) continue;
      const double ms = (events[i].getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                         events[i].getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                        1e-6;
      timings[i].ms.push_back(ms);
      timings[i].images += batch;
      events[i] = cl::Event();
    }
  }
};

OpenClBackend::OpenClBackend(const DarknetModel& model, const OpenClOptions& options) : impl_(new Impl) {
  const auto problems = options.validate();
  if (!problems.empty()) {
    std::string msg = "OpenClOptions:";
    for (const auto& p : problems) msg += " " + p + ";";
    throw std::invalid_argument(msg);
  }
  Impl& m = *impl_;
  m.options = options;
  m.device = select_opencl_device(options);
  try {
    m.context = cl::Context(m.device);
    m.queue = cl::CommandQueue(m.context, m.device, 0);
    const auto& src = opencl_sources::all();
    m.misc_program = m.build(src.at("maxpool_blocked.cl") + "\n" + src.at("upsample_blocked.cl") + "\n" +
                                 src.at("route_blocked.cl") + "\n" + src.at("layout_blocked.cl") + "\n" +
                                 src.at("winograd_blocked.cl"),
                             "");
    m.plan(model);
    m.queue.finish();
  } catch (const cl::Error& e) {
    throw std::runtime_error(describe_cl_error(e, "OpenClBackend on '" + device_name() + "'"));
  }
}

OpenClBackend::~OpenClBackend() = default;

std::string OpenClBackend::name() const { return "opencl: " + device_name(); }
Shape OpenClBackend::input_shape() const { return impl_->input_shape; }
std::vector<Shape> OpenClBackend::output_shapes() const { return impl_->output_shapes; }
int OpenClBackend::max_batch() const { return impl_->options.max_batch; }

bool OpenClBackend::is_gpu() const { return (impl_->device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) != 0; }

std::string OpenClBackend::device_name() const {
  std::string n = impl_->device.getInfo<CL_DEVICE_NAME>();
  while (!n.empty() && n.back() == '\0') n.pop_back();
  return n;
}

void OpenClBackend::set_profiling(bool on) {
  Impl& m = *impl_;
  try {
    m.queue.finish();
    m.queue = cl::CommandQueue(m.context, m.device, on ? CL_QUEUE_PROFILING_ENABLE : 0);
  } catch (const cl::Error& e) {
    throw std::runtime_error(describe_cl_error(e, "OpenClBackend::set_profiling"));
  }
  m.profiling = on;
  if (on)
    m.start_profiling();
  else
    m.events.clear();
}

std::vector<std::string> OpenClBackend::commands() const {
  const Impl& m = *impl_;
  std::vector<std::string> c;
  c.push_back(m.planar_input ? "input: host to device (planar, bordered)" : "input: host to device (staging)");
  if (!m.planar_input) c.push_back("input: pack_nchw_to_blocked");
  for (const Step& s : m.steps) c.push_back(s.what);
  for (size_t i = 0; i < m.unpacks.size(); ++i) c.push_back("output " + std::to_string(i) + ": unpack_blocked_to_nchw");
  c.push_back("output: device to host");
  return c;
}

std::vector<KernelTiming> OpenClBackend::profile() const {
  std::vector<KernelTiming> out;
  for (const KernelTiming& k : impl_->timings)
    if (!k.ms.empty()) out.push_back(k);
  return out;
}

void OpenClBackend::forward(const float* input, int batch, std::vector<float>& output) {
  Impl& m = *impl_;
  if (batch < 1 || batch > m.options.max_batch)
    throw std::invalid_argument("OpenClBackend::forward: batch " + std::to_string(batch) + " outside 1.." +
                                std::to_string(m.options.max_batch) + " (opencl.max_batch)");
  const size_t out_floats = static_cast<size_t>(output_size(m.output_shapes)) * batch;
  output.resize(out_floats);
  const Step* current = nullptr;
  try {
    m.write_input(input, batch);
    for (size_t i = 0; i < m.steps.size(); ++i) {
      current = &m.steps[i];
      m.enqueue(m.steps[i], batch, 2 + i);
    }
    for (size_t i = 0; i < m.unpacks.size(); ++i) {
      current = &m.unpacks[i];
      m.enqueue(m.unpacks[i], batch, 2 + m.steps.size() + i);
    }
    current = nullptr;
    m.queue.enqueueReadBuffer(m.staging_out, CL_TRUE, 0, out_floats * sizeof(float), output.data(), nullptr,
                              m.profiling ? &m.events.back() : nullptr);
    if (m.profiling) m.record_profile(batch);
  } catch (const cl::Error& e) {
    throw std::runtime_error(describe_cl_error(e, current ? "enqueueing " + current->what : "OpenClBackend::forward"));
  }
}

}  // namespace wingman::detector
