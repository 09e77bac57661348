// The GPU layer: headless context, RAII wrappers, shader builder error reporting.
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include <engine/gpu/context.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gpu_timer.h>
#include <engine/gpu/shader_program.h>

namespace {

engine::GpuContext headless_or_fail() {
  auto ctx = engine::GpuContext::create_headless();
  if (!ctx) {
    ADD_FAILURE() << "headless GL context creation failed: " << ctx.error().to_string();
    std::abort();
  }
  return std::move(ctx.value());
}

TEST(GpuContext, HeadlessIsOpenGl45Core) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx.ok()) << ctx.error().to_string();
  EXPECT_TRUE(ctx->headless());
  EXPECT_EQ(ctx->window(), nullptr);
  GLint major = 0;
  GLint minor = 0;
  GLint profile = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_GE(major * 10 + minor, 45) << ctx->description();
  EXPECT_NE(profile & GL_CONTEXT_CORE_PROFILE_BIT, 0);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GpuContext, TwoContextsInSequence) {
  for (int i = 0; i < 2; ++i) {
    auto ctx = engine::GpuContext::create_headless();
    ASSERT_TRUE(ctx.ok()) << ctx.error().to_string();
    EXPECT_NE(glGetString(GL_VERSION), nullptr);
  }
}

TEST(GlObjects, MoveLeavesSourceEmpty) {
  engine::GpuContext ctx = headless_or_fail();
  engine::GlBuffer a = engine::GlBuffer::create(64, nullptr);
  ASSERT_FALSE(a.empty());
  const std::uint32_t id = a.id();
  EXPECT_TRUE(glIsBuffer(id));
  engine::GlBuffer b = std::move(a);
  EXPECT_TRUE(a.empty());  // NOLINT(bugprone-use-after-move): the moved-from state is the contract
  EXPECT_EQ(b.id(), id);
  engine::GlBuffer c;
  c = std::move(b);
  EXPECT_TRUE(b.empty());  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(c.id(), id);
  c.reset();
  EXPECT_TRUE(c.empty());
  EXPECT_FALSE(glIsBuffer(id));

  engine::GlTexture t = engine::GlTexture::create_2d(GL_RGBA8, 4, 4);
  engine::GlTexture cube = engine::GlTexture::create_cube(GL_DEPTH_COMPONENT32F, 8);
  engine::GlTexture arr = engine::GlTexture::create_2d_array(GL_RGBA16F, 4, 4, 3);
  engine::GlFramebuffer fb = engine::GlFramebuffer::create();
  glNamedFramebufferTexture(fb.id(), GL_COLOR_ATTACHMENT0, t.id(), 0);
  EXPECT_TRUE(fb.complete());
  engine::GlVertexArray vao = engine::GlVertexArray::create();
  engine::GlQuery q = engine::GlQuery::create(GL_TIME_ELAPSED);
  engine::GlVertexArray vao2 = std::move(vao);
  engine::GlQuery q2 = std::move(q);
  engine::GlTexture t2 = std::move(t);
  EXPECT_TRUE(vao.empty() && q.empty() && t.empty());  // NOLINT(bugprone-use-after-move)
  EXPECT_FALSE(vao2.empty() || q2.empty() || t2.empty() || cube.empty() || arr.empty());
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// A table of shader files like the embedded one, with an error in an included file.
const engine::ShaderFile kFiles[] = {
    {"main.frag.glsl", "shaders/main.frag.glsl",
     "#version 450 core\n"
     "// line 2\n"
     "#include \"good_common.glsl\"\n"
     "#include \"bad_common.glsl\"\n"
     "out vec4 o;\n"
     "void main() { o = vec4(good(), bad(), 0.0, 1.0); }\n"},
    {"good_common.glsl", "shaders/good_common.glsl", "float good() { return 1.0; }\n"},
    {"bad_common.glsl", "shaders/bad_common.glsl",
     "// a helper\n"
     "float bad() {\n"
     "  return undefined_symbol;\n"
     "}\n"},
    {"ok.frag.glsl", "shaders/ok.frag.glsl",
     "#version 450 core\n"
     "#include \"good_common.glsl\"\n"
     "out vec4 o;\n"
     "void main() { o = vec4(good()); }\n"},
    {"late_error.frag.glsl", "shaders/late_error.frag.glsl",
     "#version 450 core\n"
     "#include \"good_common.glsl\"\n"
     "out vec4 o;\n"
     "void main() { o = vec4(good()); }\n"
     "void broken() { int x = ; }\n"},
    {"quad.vert.glsl", "shaders/quad.vert.glsl", "#version 450 core\nvoid main() { gl_Position = vec4(0.0); }\n"},
};

TEST(ShaderProgramBuilder, ErrorInIncludedFileNamesThatFileAndLine) {
  engine::GpuContext ctx = headless_or_fail();
  auto p = engine::ShaderProgramBuilder(kFiles)
               .stage(engine::ShaderStage::Vertex, "quad.vert.glsl")
               .stage(engine::ShaderStage::Fragment, "main.frag.glsl")
               .build();
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().file, "shaders/bad_common.glsl") << p.error().to_string();
  EXPECT_EQ(p.error().location, "line 3") << p.error().to_string();
  EXPECT_NE(p.error().to_string().find("shaders/bad_common.glsl: line 3: "), std::string::npos);
}

TEST(ShaderProgramBuilder, ErrorAfterIncludeMapsBackToMainFile) {
  engine::GpuContext ctx = headless_or_fail();
  auto p = engine::ShaderProgramBuilder(kFiles)
               .stage(engine::ShaderStage::Vertex, "quad.vert.glsl")
               .stage(engine::ShaderStage::Fragment, "late_error.frag.glsl")
               .build();
  ASSERT_FALSE(p.ok());
  EXPECT_EQ(p.error().file, "shaders/late_error.frag.glsl") << p.error().to_string();
  EXPECT_EQ(p.error().location, "line 5") << p.error().to_string();
}

TEST(ShaderProgramBuilder, MissingIncludeIsReported) {
  const engine::ShaderFile files[] = {
      {"a.frag.glsl", "shaders/a.frag.glsl", "#version 450 core\n\n#include \"nope_common.glsl\"\nvoid main() {}\n"}};
  auto src = engine::ShaderProgramBuilder(files).preprocess("a.frag.glsl");
  ASSERT_FALSE(src.ok());
  EXPECT_EQ(src.error().file, "shaders/a.frag.glsl");
  EXPECT_EQ(src.error().location, "line 3");
}

TEST(ShaderProgramBuilder, BuildsAndRunsEmbeddedEngineShaders) {
  engine::GpuContext ctx = headless_or_fail();
  auto ok = engine::ShaderProgramBuilder(kFiles)
                .stage(engine::ShaderStage::Vertex, "quad.vert.glsl")
                .stage(engine::ShaderStage::Fragment, "ok.frag.glsl")
                .build();
  ASSERT_TRUE(ok.ok()) << ok.error().to_string();
  EXPECT_FALSE(ok->empty());
  for (auto [vs, fs] :
       {std::pair{"forward.vert.glsl", "forward.frag.glsl"}, std::pair{"shadow.vert.glsl", "shadow.frag.glsl"},
        std::pair{"fullscreen.vert.glsl", "tonemap.frag.glsl"}}) {
    auto p = engine::ShaderProgramBuilder(engine::engine_shader_files())
                 .stage(engine::ShaderStage::Vertex, vs)
                 .stage(engine::ShaderStage::Fragment, fs)
                 .build();
    EXPECT_TRUE(p.ok()) << vs << " + " << fs << ": " << (p ? "" : p.error().to_string());
  }
}

TEST(GpuTimer, MeasuresNonNegativeWallTime) {
  engine::GpuContext ctx = headless_or_fail();
  engine::GpuTimer timer;
  engine::GlBuffer work = engine::GlBuffer::create(1 << 20, nullptr);  // some GL work to wait for
  const double a = timer.lap_ms();
  const double b = timer.lap_ms();
  EXPECT_GE(a, 0.0);
  EXPECT_GE(b, 0.0);
  EXPECT_LT(a, 1000.0);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace
