// A material's texture addressing and alpha (render/gpu_scene.h, MaterialUniform), shared by
// forward.frag.glsl and the alpha-tested depth passes (shadow.frag.glsl, depth_only.frag.glsl,
// depth_reach.frag.glsl built with ALPHA_TEST 1).
// Slots: 0 base colour, 1 metallic-roughness, 2 normal, 3 emissive.
uniform int u_alpha_mode;  // 0 OPAQUE, 1 MASK, 2 BLEND
uniform float u_alpha_cutoff;
uniform ivec4 u_texcoord_sets;  // per slot: TEXCOORD_0 or TEXCOORD_1
// Per slot two rows (xyz) of its KHR_texture_transform as a 2x3 matrix (identity: uv exactly).
uniform vec4 u_uv_transforms[8];

// The UV slot `slot` samples its texture at.
vec2 material_uv(int slot, vec2 uv0, vec2 uv1) {
  const vec3 uv = vec3(u_texcoord_sets[slot] == 1 ? uv1 : uv0, 1.0);
  return vec2(dot(u_uv_transforms[2 * slot].xyz, uv), dot(u_uv_transforms[2 * slot + 1].xyz, uv));
}

#if defined(ALPHA_TEST) && ALPHA_TEST
// The depth passes' cut-out: baseColorFactor.a x the base colour texture's alpha against the
// cutoff (MASK: the material's; BLEND: 0.5, a blended surface casts a cut-out shadow).
in vec2 v_uv0;
in vec2 v_uv1;
layout(binding = 0) uniform sampler2D u_base_color_texture;
uniform float u_base_alpha;

void alpha_test() {
  if (u_base_alpha * texture(u_base_color_texture, material_uv(0, v_uv0, v_uv1)).a < u_alpha_cutoff) discard;
}
#else
void alpha_test() {}
#endif
