#version 450 core
// A dynamic object's indirect irradiance per vertex for the renderer: the static world's
// light (probes, uploaded when the object moved) plus the light interreflected between the
// dynamic objects (the basis-radiance-field pass's output). One invocation per vertex.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer World { vec4 world[]; };
layout(std430, binding = 1) readonly buffer Interreflected { vec4 interreflected[]; };
layout(std430, binding = 2) writeonly buffer Total { vec4 total[]; };

uniform uint u_count;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  total[i] = vec4(world[i].xyz + interreflected[i].xyz, 1.0);
}
