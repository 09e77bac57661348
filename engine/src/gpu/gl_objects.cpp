#include <engine/gpu/gl_objects.h>

#include <GL/glcorearb.h>

namespace engine {

void delete_gl_object(GlObjectKind kind, std::uint32_t id) {
  if (id == 0) return;
  const GLuint name = id;
  switch (kind) {
    case GlObjectKind::Buffer:
      glDeleteBuffers(1, &name);
      break;
    case GlObjectKind::Texture:
      glDeleteTextures(1, &name);
      break;
    case GlObjectKind::Framebuffer:
      glDeleteFramebuffers(1, &name);
      break;
    case GlObjectKind::Renderbuffer:
      glDeleteRenderbuffers(1, &name);
      break;
    case GlObjectKind::VertexArray:
      glDeleteVertexArrays(1, &name);
      break;
    case GlObjectKind::Query:
      glDeleteQueries(1, &name);
      break;
    case GlObjectKind::Program:
      glDeleteProgram(name);
      break;
    case GlObjectKind::Shader:
      glDeleteShader(name);
      break;
    case GlObjectKind::Sampler:
      glDeleteSamplers(1, &name);
      break;
  }
}

GlBuffer GlBuffer::create() {
  GLuint id = 0;
  glCreateBuffers(1, &id);
  return GlBuffer(id);
}

GlBuffer GlBuffer::create(std::size_t bytes, const void* data, std::uint32_t storage_flags) {
  GlBuffer b = create();
  // Zero-sized storage is not allowed; keep a 16-byte buffer so bindings stay valid.
  glNamedBufferStorage(b.id(), static_cast<GLsizeiptr>(bytes == 0 ? 16 : bytes), bytes == 0 ? nullptr : data,
                       storage_flags);
  return b;
}

GlTexture GlTexture::create(std::uint32_t target) {
  GLuint id = 0;
  glCreateTextures(target, 1, &id);
  return GlTexture(id);
}

GlTexture GlTexture::create_2d(std::uint32_t internal_format, int width, int height, int levels) {
  GlTexture t = create(GL_TEXTURE_2D);
  glTextureStorage2D(t.id(), levels, internal_format, width, height);
  return t;
}

GlTexture GlTexture::create_2d_array(std::uint32_t internal_format, int width, int height, int layers, int levels) {
  GlTexture t = create(GL_TEXTURE_2D_ARRAY);
  glTextureStorage3D(t.id(), levels, internal_format, width, height, layers);
  return t;
}

GlTexture GlTexture::create_cube(std::uint32_t internal_format, int size, int levels) {
  GlTexture t = create(GL_TEXTURE_CUBE_MAP);
  glTextureStorage2D(t.id(), levels, internal_format, size, size);
  return t;
}

GlTexture GlTexture::create_cube_array(std::uint32_t internal_format, int size, int cubes, int levels) {
  GlTexture t = create(GL_TEXTURE_CUBE_MAP_ARRAY);
  glTextureStorage3D(t.id(), levels, internal_format, size, size, 6 * cubes);
  return t;
}

GlFramebuffer GlFramebuffer::create() {
  GLuint id = 0;
  glCreateFramebuffers(1, &id);
  return GlFramebuffer(id);
}

bool GlFramebuffer::complete() const {
  return glCheckNamedFramebufferStatus(id(), GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
}

GlRenderbuffer GlRenderbuffer::create(std::uint32_t internal_format, int width, int height) {
  GLuint id = 0;
  glCreateRenderbuffers(1, &id);
  glNamedRenderbufferStorage(id, internal_format, width, height);
  return GlRenderbuffer(id);
}

GlVertexArray GlVertexArray::create() {
  GLuint id = 0;
  glCreateVertexArrays(1, &id);
  return GlVertexArray(id);
}

GlQuery GlQuery::create(std::uint32_t target) {
  GLuint id = 0;
  glCreateQueries(target, 1, &id);
  return GlQuery(id);
}

GlSampler GlSampler::create() {
  GLuint id = 0;
  glCreateSamplers(1, &id);
  return GlSampler(id);
}

}  // namespace engine
