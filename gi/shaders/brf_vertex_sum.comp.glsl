#version 450 core
// A dynamic object's indirect irradiance per vertex for the renderer: the static world's
// light (probes, uploaded when the object moved) plus the light interreflected between the
// dynamic objects (the basis-radiance-field pass's output). One invocation per value: a
// glossy object's K x V values ([k x V + j]), its glossy terms times its glossy colour.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer World { vec4 world[]; };
layout(std430, binding = 1) readonly buffer Interreflected { vec4 interreflected[]; };
layout(std430, binding = 2) writeonly buffer Total { vec4 total[]; };

uniform uint u_count;         // values: V x K
uniform uint u_first_glossy;  // V: from here on the glossy terms E_k, drawn x the glossy colour
uniform vec3 u_specular;

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  const vec3 e = world[i].xyz + interreflected[i].xyz;
  total[i] = vec4(i < u_first_glossy ? e : e * u_specular, 1.0);
}
