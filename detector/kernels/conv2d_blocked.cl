// SPDX-License-Identifier: MIT
// Direct convolution on the 16-channel blocked, zero-bordered layout, BN folded, bias and activation fused.
//
// Tensors: [N][C/16][H+2B][W+2B][16] (channel lane fastest), border B of zeros.
// Weights: [K/16][C/16][KS*KS][16 in][16 out], read strictly in order.
// One work-item: 16 output channels x TW consecutive x positions of one row, TW float16 accumulators.
// Compile-time: TW (tile width), KS (kernel size), STRIDE, CIN (input lanes used per block: 16, or C
// when the input has a single partly filled block, e.g. 3 for an RGB first layer).
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
#define KK (KS * KS)

#define ACT_LINEAR 0
#define ACT_LEAKY 1
#define ACT_LOGISTIC 2

__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void conv2d_blocked(
    __global const float* restrict in, __global const float* restrict weights, __global const float* restrict bias,
    __global float* restrict out, const int in_cb, const int in_hp, const int in_wp,
    const int in_off,  // border of the input minus the convolution's padding
    const int out_kb, const int out_w, const int out_hp, const int out_wp, const int out_border,
    const int activation) {
  const int x0 = get_global_id(0) * TW;
  const int y = get_global_id(1);
  const int nk = get_global_id(2);
  const int n = nk / out_kb;
  const int kb = nk - n * out_kb;

  const float16 b = vload16(kb, bias);
  float16 acc[TW];
#pragma unroll
  for (int i = 0; i < TW; ++i) acc[i] = b;

  const size_t in_plane = (size_t)in_hp * in_wp * 16;
  __global const float* in_n =
      in + (size_t)n * in_cb * in_plane + ((size_t)(y * STRIDE + in_off) * in_wp + (x0 * STRIDE + in_off)) * 16;
  __global const float* w_k = weights + (size_t)kb * in_cb * KK * 256;

  for (int cb = 0; cb < in_cb; ++cb) {
    __global const float* in_c = in_n + cb * in_plane;
    __global const float* w_c = w_k + (size_t)cb * KK * 256;
    for (int t = 0; t < KK; ++t) {
      const int ky = t / KS;
      const int kx = t - ky * KS;
      __global const float* ip = in_c + (ky * in_wp + kx) * 16;
      __global const float* wp = w_c + t * 256;
#if CIN == 16
#pragma unroll 4
#else
#pragma unroll
#endif
      for (int ci = 0; ci < CIN; ++ci) {
        const float16 wv = vload16(ci, wp);
#pragma unroll
        for (int i = 0; i < TW; ++i) acc[i] = fma((float16)(ip[i * STRIDE * 16 + ci]), wv, acc[i]);
      }
    }
  }

  __global float* op = out + (size_t)n * out_kb * out_hp * out_wp * 16 +
                       ((size_t)(kb * out_hp + y + out_border) * out_wp + x0 + out_border) * 16;
  if (activation == ACT_LEAKY) {
#pragma unroll
    for (int i = 0; i < TW; ++i) acc[i] = fmax(acc[i], acc[i] * 0.1f);
  } else if (activation == ACT_LOGISTIC) {
#pragma unroll
    for (int i = 0; i < TW; ++i) acc[i] = 1.0f / (1.0f + exp(-acc[i]));
  }
  if (x0 + TW <= out_w) {
#pragma unroll
    for (int i = 0; i < TW; ++i) vstore16(acc[i], i, op);
  } else {
#pragma unroll
    for (int i = 0; i < TW; ++i)
      if (x0 + i < out_w) vstore16(acc[i], i, op);
  }
}
