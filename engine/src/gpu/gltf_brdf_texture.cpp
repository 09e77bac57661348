#include <engine/gpu/gltf_brdf_texture.h>

#include <GL/glcorearb.h>

#include <engine/gltf_brdf.h>

namespace engine {

GlTexture upload_gltf_albedo_table() {
  const GltfAlbedoTable& table = gltf_albedo_table();
  constexpr int n = GltfAlbedoTable::kSize;
  GlTexture t = GlTexture::create_2d(GL_RGBA32F, n, n);
  // node[j][i] is row j (roughness), column i (cos): the texture's (x = i, y = j).
  glTextureSubImage2D(t.id(), 0, 0, 0, n, n, GL_RGBA, GL_FLOAT, &table.node[0][0]);
  glTextureParameteri(t.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(t.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  return t;
}

}  // namespace engine
