// SPDX-License-Identifier: MIT
// OpenClBackend: plans buffers and kernels for a DarknetModel once, then forward() only enqueues.
#include "wingman/detector/opencl_backend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
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

/// A tensor of max_batch images in the blocked layout [N][C/16][H+2B][W+2B][16].
struct Tensor {
  Shape shape;
  int cb = 0, hp = 0, wp = 0, border = 0;
  size_t image_floats() const { return static_cast<size_t>(cb) * hp * wp * kBlock; }
  cl::Buffer buffer;
};

/// One kernel launch; dimension `batch_dim` of the global size is per image and scales with the batch.
struct Step {
  cl::Kernel kernel;
  size_t global[3] = {1, 1, 1};
  int dims = 2;
  int batch_dim = 1;
  std::string what;  // for error messages
};

std::string layer_name(const Layer& l, size_t index) {
  static const char* names[] = {"convolutional", "maxpool", "region", "route", "upsample", "yolo"};
  std::ostringstream s;
  s << "layer " << index << " [" << names[static_cast<int>(l.type)] << "] (cfg line " << l.cfg_line << ")";
  return s.str();
}

/// Tile width for an output width: the one of 8..13 wasting the fewest columns (ties: the larger).
/// 13 is the design point (docs/pocl-performance.md; wider tiles spill registers and were measured
/// slower here); 416-input widths are all multiples of 13.
int tile_width(int w) {
  int best = 13;
  int best_waste = (w + 12) / 13 * 13 - w;
  for (int t = 12; t >= 8; --t) {
    const int waste = (w + t - 1) / t * t - w;
    if (waste < best_waste) {
      best = t;
      best_waste = waste;
    }
  }
  return best;
}

/// Folds batch normalisation into the weights and packs them [K/16][C/16][KS*KS][16 in][16 out],
/// zero-padded; bias to [K/16*16]. Validates the weight array sizes.
void pack_convolution(const Layer& l, size_t index, std::vector<float>& packed, std::vector<float>& bias) {
  const int k_count = l.filters, c_count = l.input.c, kk = l.size * l.size;
  const size_t want = static_cast<size_t>(k_count) * c_count * kk;
  auto check = [&](const std::vector<float>& v, size_t n, const char* what) {
    if (v.size() != n)
      throw std::invalid_argument(layer_name(l, index) + ": " + what + " has " + std::to_string(v.size()) +
                                  " values, expected " + std::to_string(n) + " (weights not loaded?)");
  };
  check(l.weights, want, "weights");
  check(l.biases, static_cast<size_t>(k_count), "biases");
  std::vector<float> scale(k_count, 1.0f);
  bias.assign(static_cast<size_t>(blocks(k_count)) * kBlock, 0.0f);
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
  const int kb_count = blocks(k_count), cb_count = blocks(c_count);
  packed.assign(static_cast<size_t>(kb_count) * cb_count * kk * kBlock * kBlock, 0.0f);
  for (int k = 0; k < k_count; ++k)
    for (int c = 0; c < c_count; ++c)
      for (int t = 0; t < kk; ++t) {
        const size_t dst =
            ((((static_cast<size_t>(k / kBlock) * cb_count + c / kBlock) * kk + t) * kBlock + c % kBlock) * kBlock) +
            k % kBlock;
        packed[dst] = l.weights[(static_cast<size_t>(k) * c_count + c) * kk + t] * scale[k];
      }
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
  Shape input_shape, output_shape;
  int output_tensor = 0;
  cl::Buffer staging_in, staging_out;  // plain N x C x H x W
  Step pack, unpack;

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
      throw std::runtime_error(describe_cl_error(e, "building OpenCL program with '" + opts + "'") + "\nbuild log:\n" +
                               log);
    }
    return program;
  }

  cl::Program& conv_program(int tw, int ks, int stride, int cin) {
    std::ostringstream d;
    d << "-D TW=" << tw << " -D KS=" << ks << " -D STRIDE=" << stride << " -D CIN=" << cin;
    auto it = conv_programs.find(d.str());
    if (it == conv_programs.end())
      it = conv_programs.emplace(d.str(), build(opencl_sources::all().at("conv2d_blocked.cl"), d.str())).first;
    return it->second;
  }

  int add_tensor(const Shape& s, int border) {
    Tensor t;
    t.shape = s;
    t.cb = blocks(s.c);
    t.border = border;
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
    add_tensor(input_shape, border);
    std::vector<int> layer_tensor(model.layers.size(), 0);
    int current = 0;
    for (size_t i = 0; i < model.layers.size(); ++i) {
      const Layer& l = model.layers[i];
      const std::string name = layer_name(l, i);
      if (l.type != LayerType::kRoute && !(tensors[current].shape == l.input))
        throw std::invalid_argument(name + ": input shape does not follow the previous layer's output");
      switch (l.type) {
        case LayerType::kConvolutional:
          current = plan_convolution(l, i, current, border);
          break;
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
      if (l.type != LayerType::kRegion && l.type != LayerType::kYolo) output_tensor = current;
    }
    output_shape = tensors[output_tensor].shape;

    staging_in = cl::Buffer(context, CL_MEM_READ_ONLY, input_shape.size() * options.max_batch * sizeof(float));
    staging_out = cl::Buffer(context, CL_MEM_WRITE_ONLY, output_shape.size() * options.max_batch * sizeof(float));
    pack = layout_step("pack_nchw_to_blocked", staging_in, tensors[0]);
    unpack = layout_step("unpack_blocked_to_nchw", tensors[output_tensor].buffer, tensors[output_tensor]);
    unpack.kernel.setArg(0, tensors[output_tensor].buffer);
    unpack.kernel.setArg(1, staging_out);
  }

  Step layout_step(const char* kernel_name, const cl::Buffer& plain, const Tensor& t) {
    Step s;
    s.what = kernel_name;
    s.kernel = cl::Kernel(misc_program, kernel_name);
    s.kernel.setArg(0, plain);
    s.kernel.setArg(1, t.buffer);
    const int args[] = {t.shape.c, t.cb, t.shape.h, t.shape.w, t.hp, t.wp, t.border};
    for (int a = 0; a < 7; ++a) s.kernel.setArg(2 + a, args[a]);
    s.global[0] = t.shape.h;
    s.global[1] = t.shape.c;
    return s;
  }

  int plan_convolution(const Layer& l, size_t index, int in, int border) {
    if (l.size < 1 || l.stride < 1 || l.padding < 0 || l.padding > border)
      throw std::invalid_argument(layer_name(l, index) + ": unsupported size/stride/padding");
    std::vector<float> packed, bias;
    pack_convolution(l, index, packed, bias);
    const int out = add_tensor(l.output, border);
    const Tensor& ti = tensors[in];
    const Tensor& to = tensors[out];
    const int tw = tile_width(to.shape.w);
    const int cin = ti.cb == 1 ? ti.shape.c : kBlock;
    Step s;
    s.what = layer_name(l, index);
    s.kernel = cl::Kernel(conv_program(tw, l.size, l.stride, cin), "conv2d_blocked");
    s.kernel.setArg(0, ti.buffer);
    s.kernel.setArg(1, constant(packed));
    s.kernel.setArg(2, constant(bias));
    s.kernel.setArg(3, to.buffer);
    const int args[] = {ti.cb, ti.hp, ti.wp,     ti.border - l.padding,        to.cb, to.shape.w,
                        to.hp, to.wp, to.border, activation_code(l.activation)};
    for (int a = 0; a < 10; ++a) s.kernel.setArg(4 + a, args[a]);
    s.global[0] = (to.shape.w + tw - 1) / tw;
    s.global[1] = to.shape.h;
    s.global[2] = to.cb;
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
      Step s;
      s.what = layer_name(l, index);
      s.kernel = cl::Kernel(misc_program, "route_copy_blocked");
      s.kernel.setArg(0, ti.buffer);
      s.kernel.setArg(1, to.buffer);
      const int args[] = {ti.shape.c, ti.cb, to.cb, offset, to.shape.h, to.shape.w, to.hp, to.wp, to.border};
      for (int a = 0; a < 9; ++a) s.kernel.setArg(2 + a, args[a]);
      s.global[0] = to.shape.h;
      s.global[1] = ti.shape.c;
      steps.push_back(std::move(s));
      offset += ti.shape.c;
    }
    if (offset != tensors[out].shape.c)
      throw std::invalid_argument(layer_name(l, index) + ": routed channels do not add up to the output's");
    return out;
  }

  void enqueue(const Step& s, int batch) {
    size_t g[3] = {s.global[0], s.global[1], s.global[2]};
    g[s.batch_dim] *= static_cast<size_t>(batch);
    const cl::NDRange global = s.dims == 3 ? cl::NDRange(g[0], g[1], g[2]) : cl::NDRange(g[0], g[1]);
    const cl::NDRange local = s.dims == 3 ? cl::NDRange(1, 1, 1) : cl::NDRange(1, 1);
    if (profile) {
      cl::Event e;
      queue.enqueueNDRangeKernel(s.kernel, cl::NullRange, global, local, nullptr, &e);
      events.emplace_back(s.what, e);
    } else {
      queue.enqueueNDRangeKernel(s.kernel, cl::NullRange, global, local);
    }
  }
  bool profile = std::getenv("WINGMAN_OPENCL_PROFILE") != nullptr;  // per-kernel times on stderr
  std::vector<std::pair<std::string, cl::Event>> events;
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
    m.queue = cl::CommandQueue(m.context, m.device, m.profile ? CL_QUEUE_PROFILING_ENABLE : 0);
    const auto& src = opencl_sources::all();
    m.misc_program = m.build(src.at("maxpool_blocked.cl") + "\n" + src.at("upsample_blocked.cl") + "\n" +
                                 src.at("route_blocked.cl") + "\n" + src.at("layout_blocked.cl"),
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
Shape OpenClBackend::output_shape() const { return impl_->output_shape; }
int OpenClBackend::max_batch() const { return impl_->options.max_batch; }

bool OpenClBackend::is_gpu() const { return (impl_->device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) != 0; }

std::string OpenClBackend::device_name() const {
  std::string n = impl_->device.getInfo<CL_DEVICE_NAME>();
  while (!n.empty() && n.back() == '\0') n.pop_back();
  return n;
}

void OpenClBackend::forward(const float* input, int batch, std::vector<float>& output) {
  Impl& m = *impl_;
  if (batch < 1 || batch > m.options.max_batch)
    throw std::invalid_argument("OpenClBackend::forward: batch " + std::to_string(batch) + " outside 1.." +
                                std::to_string(m.options.max_batch) + " (opencl.max_batch)");
  const size_t in_floats = static_cast<size_t>(m.input_shape.size()) * batch;
  const size_t out_floats = static_cast<size_t>(m.output_shape.size()) * batch;
  output.resize(out_floats);
  const Step* current = nullptr;
  try {
    m.queue.enqueueWriteBuffer(m.staging_in, CL_FALSE, 0, in_floats * sizeof(float), input);
    current = &m.pack;
    m.enqueue(m.pack, batch);
    for (const Step& s : m.steps) {
      current = &s;
      m.enqueue(s, batch);
    }
    current = &m.unpack;
    m.enqueue(m.unpack, batch);
    current = nullptr;
    m.queue.enqueueReadBuffer(m.staging_out, CL_TRUE, 0, out_floats * sizeof(float), output.data());
    for (auto& [what, e] : m.events)
      std::fprintf(
          stderr, "%8.3f ms  %s\n",
          (e.getProfilingInfo<CL_PROFILING_COMMAND_END>() - e.getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-6,
          what.c_str());
    m.events.clear();
  } catch (const cl::Error& e) {
    throw std::runtime_error(describe_cl_error(e, current ? "enqueueing " + current->what : "OpenClBackend::forward"));
  }
}

}  // namespace wingman::detector
