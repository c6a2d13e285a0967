// SPDX-License-Identifier: MIT
// Direct convolution on the 16-channel blocked, zero-bordered layout, BN folded, bias and activation fused.
//
// Tensors: [N][C/16][H+2B][W+2B][16] (channel lane fastest), border B of zeros. With PLANAR the input is
// instead [N][C][H+2B][W+2B] (one zero-bordered plane per channel, C <= 16): the network input, written
// there by the host without a layout kernel.
// Weights: [K/(16 KBW)][C/16][KS*KS][16 in][16 KBW out], read strictly in order (PLANAR:
// [K/(16 KBW)][C][KS*KS][16 KBW out]); with w_groups > 1, image n uses weight set n % w_groups (the
// 1x1 convolutions of winograd_blocked.cl, one weight set per transformed position).
// One work-item: 16 KBW output channels x TW consecutive x positions of one output row.
// Registers: KBW x TW float16 accumulators, KBW weight vectors and one broadcast input. With KBW = 2 each
// broadcast input feeds two FMAs: broadcasts, not FMAs, limit the KBW = 1 loop on AVX-512 (measured
// ~170 vs ~230 GFLOP/s on two cores, docs/benchmarks.md).
// With POOL (a following Darknet [maxpool] size 2 stride 2 fused in), the work-item computes the two
// convolution rows of one pooled row in turn, takes the maximum of horizontal pairs in registers, parks
// the first row's maxima in `out` and finishes with the second's: the full-resolution output is never
// written. Bias is per channel and the activations are increasing, so pooling before them is exact.
// Compile-time: TW (tile width, even with POOL), KS (kernel size), STRIDE, CIN (input lanes used per
// block: 16, or C when the input has a single partly filled block, e.g. 3 for an RGB first layer), KBW
// (1 or 2 output blocks per work-item), PLANAR (0 or 1), POOL (0 or 1).
#ifndef TW
#define TW 13
#endif
#ifndef KS
#define KS 3
#endif
#ifndef STRIDE
#define STRIDE 1
#endif
#ifndef CIN
#define CIN 16
#endif
#ifndef KBW
#define KBW 2
#endif
#ifndef PLANAR
#define PLANAR 0
#endif
#ifndef POOL
#define POOL 0
#endif
#if POOL
#define SUB_ROWS 2  // convolution rows per output row
#else
#define SUB_ROWS 1
#endif
#define KK (KS * KS)
#define KOUT (16 * KBW)
#if PLANAR
#define LANE 1  // distance between two x positions of one channel, floats
#define WIN 1   // input channels per weight block
#else
#define LANE 16
#define WIN 16
#endif

#define ACT_LINEAR 0
#define ACT_LEAKY 1
#define ACT_LOGISTIC 2

inline float16 activate(float16 v, const int activation) {
  if (activation == ACT_LEAKY) return fmax(v, v * 0.1f);
  if (activation == ACT_LOGISTIC) return 1.0f / (1.0f + exp(-v));
  return v;
}

__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void conv2d_blocked(
    __global const float* restrict in, __global const float* restrict weights, __global const float* restrict bias,
    __global float* restrict out,
    const int in_cb,  // input channel blocks (PLANAR: input channels)
    const int in_hp, const int in_wp,
    const int in_off,  // border of the input minus the convolution's padding
    const int out_kb,
    const int conv_h, const int conv_w,  // convolution output size (before the fused pooling, if any)
    const int out_hp, const int out_wp, const int out_border,  // the output tensor (pooled, if POOL)
    const int activation,
    const int w_groups) {  // images cycle through this many weight sets (Winograd: the 16 positions), else 1
  const int k_groups = (out_kb + KBW - 1) / KBW;
  const int nk = get_global_id(2);
  const int n = nk / k_groups;
  const int kb = (nk - n * k_groups) * KBW;
  const int y = get_global_id(1);          // output row
  const int x0 = get_global_id(0) * TW;    // convolution column
  const int valid = min(TW, conv_w - x0);  // real columns of the tile

#if PLANAR
  const size_t in_plane = (size_t)in_hp * in_wp;
#else
  const size_t in_plane = (size_t)in_hp * in_wp * 16;
#endif
  __global const float* w_k =
      weights + ((size_t)(n % w_groups) * k_groups + kb / KBW) * in_cb * KK * WIN * KOUT;
  const size_t out_block = (size_t)out_hp * out_wp * 16;
  __global float* op = out + ((size_t)n * out_kb + kb) * out_block +
                       ((size_t)(y + out_border) * out_wp + x0 / SUB_ROWS + out_border) * 16;
  const bool second = KBW == 2 && kb + 1 < out_kb;

  for (int sub = 0; sub < SUB_ROWS; ++sub) {
    const int cy = y * SUB_ROWS + sub;  // convolution row
    if (cy >= conv_h) break;
    float16 acc0[TW];
#if KBW == 2
    float16 acc1[TW];
#endif
    {
      const float16 b0 = vload16(kb, bias);
#if KBW == 2
      const float16 b1 = vload16(kb + 1, bias);
#endif
#pragma unroll
      for (int i = 0; i < TW; ++i) {
        acc0[i] = b0;
#if KBW == 2
        acc1[i] = b1;
#endif
      }
    }
    __global const float* in_n =
        in + (size_t)n * in_cb * in_plane + ((size_t)(cy * STRIDE + in_off) * in_wp + (x0 * STRIDE + in_off)) * LANE;

    for (int cb = 0; cb < in_cb; ++cb) {
      __global const float* in_c = in_n + cb * in_plane;
      __global const float* w_c = w_k + (size_t)cb * KK * WIN * KOUT;
      for (int t = 0; t < KK; ++t) {
        const int ky = t / KS;
        const int kx = t - ky * KS;
        __global const float* ip = in_c + (ky * in_wp + kx) * LANE;
        __global const float* wp = w_c + t * WIN * KOUT;
#if PLANAR
        // One channel per plane: the block loop (over planes) is the channel loop.
        {
          const int ci = 0;
#else
#if CIN == 16
#pragma unroll 4
#else
#pragma unroll
#endif
        for (int ci = 0; ci < CIN; ++ci) {
#endif
          const float16 w0 = vload16(ci * KBW, wp);
#if KBW == 2
          const float16 w1 = vload16(ci * KBW + 1, wp);
#endif
#pragma unroll
          for (int i = 0; i < TW; ++i) {
            const float16 x = (float16)(ip[i * STRIDE * LANE + ci]);
            acc0[i] = fma(x, w0, acc0[i]);
#if KBW == 2
            acc1[i] = fma(x, w1, acc1[i]);
#endif
          }
        }
      }
    }

#if POOL
    // Maxima of horizontal pairs (a lone last column pools alone); the first row's wait in `out`
    // (interior only: the border stays zero).
    const bool done = sub == 1 || cy + 1 >= conv_h;
#pragma unroll
    for (int j = 0; j < TW / 2; ++j) {
      if (2 * j >= valid) continue;
      float16 m0 = 2 * j + 1 < valid ? fmax(acc0[2 * j], acc0[2 * j + 1]) : acc0[2 * j];
      if (sub == 1) m0 = fmax(m0, vload16(j, op));
      vstore16(done ? activate(m0, activation) : m0, j, op);
#if KBW == 2
      if (second) {
        float16 m1 = 2 * j + 1 < valid ? fmax(acc1[2 * j], acc1[2 * j + 1]) : acc1[2 * j];
        if (sub == 1) m1 = fmax(m1, vload16(j, op + out_block));
        vstore16(done ? activate(m1, activation) : m1, j, op + out_block);
      }
#endif
    }
#else
#pragma unroll
    for (int i = 0; i < TW; ++i)
      if (i < valid) vstore16(activate(acc0[i], activation), i, op);
#if KBW == 2
    if (second) {
#pragma unroll
      for (int i = 0; i < TW; ++i)
        if (i < valid) vstore16(activate(acc1[i], activation), i, op + out_block);
    }
#endif
#endif
  }
}
