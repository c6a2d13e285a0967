// SPDX-License-Identifier: MIT
// Darknet max-pooling on the 16-channel blocked layout: window `size`, `stride`, `pad_lt` pixels of
// padding before the first row/column; cells outside the input are ignored (-inf), as in Darknet.
// One work-item: one output row of one channel block of one image.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void maxpool_blocked(
    __global const float* restrict in, __global float* restrict out, const int cb, const int in_h, const int in_w,
    const int in_hp, const int in_wp, const int in_border, const int out_w, const int out_hp, const int out_wp,
    const int out_border, const int size, const int stride, const int pad_lt) {
  const int y = get_global_id(0);
  const int nc = get_global_id(1);  // n * cb + c
  __global const float* in_c = in + (size_t)nc * in_hp * in_wp * 16;
  __global float* out_row = out + ((size_t)nc * out_hp + y + out_border) * out_wp * 16 + out_border * 16;
  const int y0 = y * stride - pad_lt;
  const int ya = max(y0, 0);
  const int yb = min(y0 + size, in_h);
  for (int x = 0; x < out_w; ++x) {
    const int x0 = x * stride - pad_lt;
    const int xa = max(x0, 0);
    const int xb = min(x0 + size, in_w);
    float16 m = (float16)(-INFINITY);
    for (int iy = ya; iy < yb; ++iy) {
      __global const float* row = in_c + ((size_t)(iy + in_border) * in_wp + in_border) * 16;
      for (int ix = xa; ix < xb; ++ix) m = fmax(m, vload16(ix, row));
    }
    vstore16(m, x, out_row);
  }
}
