// Shared declarations of the antiradiance passes (Dachsbacher et al. 2007, §4;
// gi/src/antiradiance/antiradiance_gpu_pass.cpp fills the buffers). Tables are flat float
// arrays, three floats (RGB) per (row, bin): entry (row * u_bins + bin) * 3 + channel.
// Work groups lie on a 2-D grid (65535 groups per dimension on llvmpipe).

layout(local_size_x = 64) in;

uniform uint u_bins;   // m
uniform uint u_items;  // invocations that do work in this dispatch

uint item_index() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  return group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
}
