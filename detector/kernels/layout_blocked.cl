// SPDX-License-Identifier: MIT
// Conversions between plain N x C x H x W tensors and the 16-channel blocked, zero-bordered layout.
// One work-item: one row of one channel of one image.
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void pack_nchw_to_blocked(
    __global const float* restrict in, __global float* restrict out, const int c_count, const int cb, const int h,
    const int w, const int hp, const int wp, const int border) {
  const int y = get_global_id(0);
  const int nc = get_global_id(1);  // n * c_count + c
  const int n = nc / c_count;
  const int c = nc - n * c_count;
  __global const float* src = in + ((size_t)nc * h + y) * w;
  __global float* dst = out + (((size_t)(n * cb + c / 16) * hp + y + border) * wp + border) * 16 + (c % 16);
  for (int x = 0; x < w; ++x) dst[x * 16] = src[x];
}

// Unpacking writes image n's tensor at out + n * out_image + out_offset (several outputs per image).
__kernel __attribute__((reqd_work_group_size(1, 1, 1))) void unpack_blocked_to_nchw(
    __global const float* restrict in, __global float* restrict out, const int c_count, const int cb, const int h,
    const int w, const int hp, const int wp, const int border, const long out_image, const long out_offset) {
  const int y = get_global_id(0);
  const int nc = get_global_id(1);
  const int n = nc / c_count;
  const int c = nc - n * c_count;
  __global const float* src = in + (((size_t)(n * cb + c / 16) * hp + y + border) * wp + border) * 16 + (c % 16);
  __global float* dst = out + n * out_image + out_offset + ((size_t)c * h + y) * w;
  for (int x = 0; x < w; ++x) dst[x] = src[x * 16];
}
