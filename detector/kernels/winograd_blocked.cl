// SPDX-License-Identifier: MIT
// Winograd F(2x2, 3x3) transforms for 3x3 stride-1 pad-1 convolutions on the 16-channel blocked layout.
//
// A convolution becomes: winograd_input (V = B^T d B for every 4x4 input tile d, stride 2), then 16
// independent 1x1 convolutions, one per transformed position xi (conv2d_blocked with KS=1 and
// `w_groups` = 16, weights U = G g G^T packed per xi on the host), then winograd_output
// (Y = A^T M A for every tile, plus bias and activation). 16 multiplications per 2x2 outputs and input
// channel instead of 36. With
//   B^T = [1 0 -1 0; 0 1 1 0; 0 -1 1 0; 0 1 0 -1],  A^T = [1 1 1 0; 0 1 -1 -1].
// V and M: [N][16 xi][C/16][1][v_w][16] (a 1 x v_w "image" of tiles per xi, tile = ty * tiles_w + tx,
// v_w >= tiles_w * tiles_h rounded up to the 1x1 convolution's tile width).
// One work-item: one tile of one channel block of one image, 16 channels in a float16.

#define ACT_LINEAR 0
#define ACT_LEAKY 1
#define ACT_LOGISTIC 2

__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void winograd_input(
    __global const float* restrict in, __global float* restrict v, const int in_cb, const int in_hp, const int in_wp,
    const int in_border, const int tiles_w, const int v_w) {
  const int tx = get_global_id(0);
  const int ty = get_global_id(1);
  const int ncb = get_global_id(2);  // n * in_cb + cb
  const int n = ncb / in_cb;
  const int cb = ncb - n * in_cb;
  // Top-left of the tile in the bordered input: output (2 ty, 2 tx) minus the padding of 1.
  const int r0 = 2 * ty + in_border - 1;
  const int c0 = 2 * tx + in_border - 1;
  __global const float* plane = in + (size_t)ncb * in_hp * in_wp * 16;
  float16 d[4][4];
#pragma unroll
  for (int r = 0; r < 4; ++r)
#pragma unroll
    for (int c = 0; c < 4; ++c)
      d[r][c] = (r0 + r < in_hp && c0 + c < in_wp) ? vload16((r0 + r) * in_wp + c0 + c, plane) : (float16)(0.0f);
  // Rows: t = B^T d.
  float16 t[4][4];
#pragma unroll
  for (int c = 0; c < 4; ++c) {
    t[0][c] = d[0][c] - d[2][c];
    t[1][c] = d[1][c] + d[2][c];
    t[2][c] = d[2][c] - d[1][c];
    t[3][c] = d[1][c] - d[3][c];
  }
  // Columns: V = t B.
  const size_t xi_stride = (size_t)in_cb * v_w * 16;
  __global float* out = v + ((size_t)n * 16 * in_cb + cb) * v_w * 16 + (size_t)(ty * tiles_w + tx) * 16;
#pragma unroll
  for (int r = 0; r < 4; ++r) {
    vstore16(t[r][0] - t[r][2], 0, out + (4 * r + 0) * xi_stride);
    vstore16(t[r][1] + t[r][2], 0, out + (4 * r + 1) * xi_stride);
    vstore16(t[r][2] - t[r][1], 0, out + (4 * r + 2) * xi_stride);
    vstore16(t[r][1] - t[r][3], 0, out + (4 * r + 3) * xi_stride);
  }
}

__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void winograd_output(
    __global const float* restrict m, __global const float* restrict bias, __global float* restrict out,
    const int out_kb, const int tiles_w, const int v_w, const int out_h, const int out_w, const int out_hp,
    const int out_wp, const int out_border, const int activation) {
  const int tx = get_global_id(0);
  const int ty = get_global_id(1);
  const int nkb = get_global_id(2);  // n * out_kb + kb
  const int n = nkb / out_kb;
  const int kb = nkb - n * out_kb;
  const size_t xi_stride = (size_t)out_kb * v_w * 16;
  __global const float* src = m + ((size_t)n * 16 * out_kb + kb) * v_w * 16 + (size_t)(ty * tiles_w + tx) * 16;
  // Rows: s = A^T M.
  float16 s[2][4];
#pragma unroll
  for (int c = 0; c < 4; ++c) {
    const float16 m0 = vload16(0, src + (0 + c) * xi_stride);
    const float16 m1 = vload16(0, src + (4 + c) * xi_stride);
    const float16 m2 = vload16(0, src + (8 + c) * xi_stride);
    const float16 m3 = vload16(0, src + (12 + c) * xi_stride);
    s[0][c] = m0 + m1 + m2;
    s[1][c] = m1 - m2 - m3;
  }
  const float16 b = vload16(kb, bias);
  __global float* dst = out + ((size_t)nkb * out_hp + 2 * ty + out_border) * out_wp * 16 + (2 * tx + out_border) * 16;
#pragma unroll
  for (int r = 0; r < 2; ++r) {
    if (2 * ty + r >= out_h) break;
    // Columns: Y = s A.
    float16 y[2];
    y[0] = s[r][0] + s[r][1] + s[r][2] + b;
    y[1] = s[r][1] - s[r][2] - s[r][3] + b;
#pragma unroll
    for (int c = 0; c < 2; ++c) {
      if (2 * tx + c >= out_w) break;
      float16 v = y[c];
      if (activation == ACT_LEAKY) v = fmax(v, v * 0.1f);
      if (activation == ACT_LOGISTIC) v = 1.0f / (1.0f + exp(-v));
      vstore16(v, r * out_wp + c, dst);
    }
  }
}
