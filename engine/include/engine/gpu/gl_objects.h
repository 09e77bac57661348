#pragma once
// Move-only RAII owners of OpenGL object names. A moved-from owner holds 0 and deletes
// nothing. Creating or destroying one needs a current context.
//   engine::GlBuffer vbo = engine::GlBuffer::create();
//   glNamedBufferData(vbo.id(), bytes, data, GL_STATIC_DRAW);

#include <cstdint>
#include <utility>

namespace engine {

/// How a GL object name is released (one function per GL object kind).
enum class GlObjectKind : std::uint8_t {
  Buffer,
  Texture,
  Framebuffer,
  Renderbuffer,
  VertexArray,
  Query,
  Program,
  Shader,
  Sampler
};

/// Deletes `id` of the given kind (glDeleteBuffers, glDeleteProgram...). 0 is ignored.
void delete_gl_object(GlObjectKind kind, std::uint32_t id);

/// Owner of one GL object name of kind K.
template <GlObjectKind K>
class GlObject {
 public:
  GlObject() = default;
  /// Takes ownership of an existing name (0: empty).
  explicit GlObject(std::uint32_t id) : id_(id) {}
  GlObject(GlObject&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlObject& operator=(GlObject&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;
  ~GlObject() { reset(); }

  std::uint32_t id() const { return id_; }
  bool empty() const { return id_ == 0; }
  explicit operator bool() const { return id_ != 0; }
  /// Deletes the object now; the owner becomes empty.
  void reset() {
    if (id_ != 0) delete_gl_object(K, id_);
    id_ = 0;
  }
  /// Gives up ownership without deleting.
  std::uint32_t release() { return std::exchange(id_, 0); }

 private:
  std::uint32_t id_ = 0;
};

class GlBuffer : public GlObject<GlObjectKind::Buffer> {
 public:
  using GlObject::GlObject;
  /// glCreateBuffers.
  static GlBuffer create();
  /// glCreateBuffers + glNamedBufferStorage(bytes, data, flags); flags 0: immutable, GPU only.
  static GlBuffer create(std::size_t bytes, const void* data, std::uint32_t storage_flags = 0);
};

class GlTexture : public GlObject<GlObjectKind::Texture> {
 public:
  using GlObject::GlObject;
  /// glCreateTextures(target) (GL_TEXTURE_2D, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_2D_ARRAY...).
  static GlTexture create(std::uint32_t target);
  /// An immutable 2-D texture with `levels` mip levels of `internal_format`.
  static GlTexture create_2d(std::uint32_t internal_format, int width, int height, int levels = 1);
  /// An immutable 2-D array texture (`layers` layers).
  static GlTexture create_2d_array(std::uint32_t internal_format, int width, int height, int layers, int levels = 1);
  /// An immutable cube map (six faces of size x size).
  static GlTexture create_cube(std::uint32_t internal_format, int size, int levels = 1);
  /// An immutable cube map array with `cubes` cube maps (6 x cubes layer-faces).
  static GlTexture create_cube_array(std::uint32_t internal_format, int size, int cubes, int levels = 1);
};

class GlFramebuffer : public GlObject<GlObjectKind::Framebuffer> {
 public:
  using GlObject::GlObject;
  static GlFramebuffer create();
  /// True when glCheckNamedFramebufferStatus says GL_FRAMEBUFFER_COMPLETE.
  bool complete() const;
};

class GlRenderbuffer : public GlObject<GlObjectKind::Renderbuffer> {
 public:
  using GlObject::GlObject;
  static GlRenderbuffer create(std::uint32_t internal_format, int width, int height);
};

class GlVertexArray : public GlObject<GlObjectKind::VertexArray> {
 public:
  using GlObject::GlObject;
  static GlVertexArray create();
};

class GlQuery : public GlObject<GlObjectKind::Query> {
 public:
  using GlObject::GlObject;
  /// glCreateQueries(target), e.g. GL_TIME_ELAPSED (meaningless on llvmpipe; see GpuTimer).
  static GlQuery create(std::uint32_t target);
};

class GlSampler : public GlObject<GlObjectKind::Sampler> {
 public:
  using GlObject::GlObject;
  static GlSampler create();
};

class GlShader : public GlObject<GlObjectKind::Shader> {
 public:
  using GlObject::GlObject;
};

class GlProgram : public GlObject<GlObjectKind::Program> {
 public:
  using GlObject::GlObject;
};

}  // namespace engine
