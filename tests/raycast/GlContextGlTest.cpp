// Headless EGL context and GL objects: the shared C++/GLSL math (Morton codes, TEA jitter) gives
// the same results on the GPU as in C++ on random inputs; shader errors carry the info log;
// buffers and timer queries work. Skips only when EglContext::create throws gl::Unavailable.
#include <gtest/gtest.h>

#include "GlTestSupport.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/Morton.h"
#include "gl/EglContext.h"
#include "gl/Objects.h"
#include "gl/ShaderSource.h"
#include "streaming/Jitter.h"

namespace {

namespace gl = flipscope::gl;

class GlContext : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      context = gl::EglContext::create();
    } catch (const gl::Unavailable& e) {
      FLIPSCOPE_SKIP_WITHOUT_GL(e.what());
    }
  }
  gl::EglContext context;
};

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

TEST(ShaderSource, PastesIncludesOnceAfterTheVersionLine) {
  const std::string source = gl::shaderSource("SharedMathTest.comp");
  EXPECT_EQ(source.rfind("#version 450 core\n#define FS_FUNC\n", 0), 0u) << source.substr(0, 80);
  EXPECT_EQ(count(source, "#version"), 1u);
  EXPECT_EQ(count(source, "FS_FUNC uint mortonEncode3("), 1u) << "Morton.glsl is included twice, pasted once";
  EXPECT_EQ(count(source, "FS_FUNC vec3 cellJitter("), 1u);
  EXPECT_EQ(count(source, "#include"), 0u);
  EXPECT_LT(source.find("mortonEncode3("), source.find("cellJitter("));
}

TEST(ShaderSource, UnknownFileIsNamed) {
  try {
    gl::shaderSource("NoSuchShader.comp");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("NoSuchShader.comp"), std::string::npos) << e.what();
  }
}

TEST_F(GlContext, IsOpenGl45CoreAndMovable) {
  std::cout << "[          ] platform " << context.platform() << ": " << context.renderer() << "\n";
  EXPECT_TRUE(context.isValid());
  EXPECT_TRUE(context.platform() == "device" || context.platform() == "surfaceless" || context.platform() == "default")
      << context.platform();
  EXPECT_GE(epoxy_gl_version(), 45);
  GLint profile = 0;
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  EXPECT_TRUE(profile & GL_CONTEXT_CORE_PROFILE_BIT);
  EXPECT_EQ(count(context.renderer(), " / "), 2u) << context.renderer();

  gl::EglContext moved = std::move(context);
  EXPECT_TRUE(moved.isValid());
  EXPECT_FALSE(context.isValid());  // NOLINT(bugprone-use-after-move): moved-from is empty
  moved.makeCurrent();
  EXPECT_NE(moved.renderer().find("4.5"), std::string::npos) << moved.renderer();
}

TEST_F(GlContext, TwoContextsShareTheDisplaySafely) {
  gl::EglContext second = gl::EglContext::create();  // now current
  EXPECT_EQ(second.display(), context.display()) << "one display per platform";
  second = gl::EglContext();  // destroys it; the display must stay usable for `context`
  context.makeCurrent();
  gl::Buffer buffer(16);
  EXPECT_EQ(buffer.size(), 16u);
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

// Morton codes bit for bit; jitter within one float rounding of the C++ (the count of bit-exact
// components is printed).
TEST_F(GlContext, SharedMathMatchesCpu) {
  const gl::Program program = gl::Program::compute(gl::shaderSource("SharedMathTest.comp"), "SharedMathTest.comp");
  constexpr std::uint32_t kCount = 1000;
  constexpr float kMaxJitter = 0.35f;
  std::mt19937 rng(20140623);
  std::uniform_int_distribution<std::uint32_t> cell(0, (1u << 20) - 1);
  std::uniform_int_distribution<std::uint32_t> word;
  std::vector<glm::uvec4> inputs(kCount);
  for (glm::uvec4& v : inputs) v = glm::uvec4(cell(rng), cell(rng), cell(rng), word(rng));
  inputs[0] = glm::uvec4(0, 0, 0, 0);  // edges: the origin, the last cell, small cells
  inputs[1] = glm::uvec4((1u << 20) - 1, (1u << 20) - 1, (1u << 20) - 1, 0xffffffffu);
  inputs[2] = glm::uvec4(1, 2, 3, 1);

  struct Params {
    std::uint32_t count;
    float maxJitter;
    std::uint32_t pad[2];
  } params{kCount, kMaxJitter, {0, 0}};
  gl::Buffer paramBuffer(sizeof params, &params);
  gl::Buffer inputBuffer(inputs.size() * sizeof(glm::uvec4), inputs.data());
  gl::Buffer mortonBuffer(kCount * 4);
  gl::Buffer jitterBuffer(kCount * sizeof(glm::vec4));
  mortonBuffer.clearZero();
  paramBuffer.bindBase(GL_UNIFORM_BUFFER, 0);
  inputBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  mortonBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  jitterBuffer.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
  program.use();
  program.dispatch((kCount + 63) / 64);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> mortons(kCount);
  std::vector<glm::vec4> jitters(kCount);
  mortonBuffer.download(0, kCount * 4, mortons.data());
  jitterBuffer.download(0, kCount * sizeof(glm::vec4), jitters.data());
  ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));

  std::size_t exactJitter = 0;
  for (std::uint32_t i = 0; i < kCount; ++i) {
    const glm::uvec4 v = inputs[i];
    ASSERT_EQ(mortons[i], flipscope::mortonEncode3(v.x & 1023u, v.y & 1023u, v.z & 1023u)) << "input " << i;
    const glm::vec3 cpu = flipscope::cellJitter(glm::uvec3(v), v.w, kMaxJitter);
    for (int c = 0; c < 3; ++c) {
      // jitterFromHash rounds once at the end; relative to the jitter scale.
      EXPECT_NEAR(jitters[i][c], cpu[c], 1e-6f * kMaxJitter) << "input " << i << " axis " << c;
      EXPECT_GE(jitters[i][c], -kMaxJitter);
      EXPECT_LT(jitters[i][c], kMaxJitter);
      exactJitter += jitters[i][c] == cpu[c];
    }
  }
  std::cout << "[          ] " << exactJitter << " of " << 3 * kCount << " jitter components bit-exact\n";
}

TEST_F(GlContext, BadShaderThrowsWithInfoLogAndNumberedSource) {
  const std::string source =
      "#version 450 core\n"
      "layout(local_size_x = 1) in;\n"
      "void main() { undeclaredVariable = 1; }\n";
  try {
    gl::Program::compute(source, "Broken.comp");
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("Broken.comp: compilation failed", 0), 0u) << what;
    EXPECT_NE(what.find("undeclaredVariable"), std::string::npos) << what;  // from the info log
    EXPECT_NE(what.find("    3| void main()"), std::string::npos) << what;
  }
}

TEST_F(GlContext, BufferRoundTripAndClear) {
  std::vector<std::uint32_t> data(64);
  for (std::uint32_t i = 0; i < data.size(); ++i) data[i] = i * 2654435761u;
  gl::Buffer buffer(data.size() * 4, data.data());
  EXPECT_EQ(buffer.size(), data.size() * 4);
  EXPECT_NE(buffer.id(), 0u);
  const std::uint32_t patch[2] = {7, 9};
  buffer.upload(8, patch, sizeof patch);
  std::vector<std::uint32_t> back(data.size());
  buffer.download(0, back.size() * 4, back.data());
  data[2] = 7;
  data[3] = 9;
  EXPECT_EQ(back, data);
  buffer.clearZero();
  buffer.download(0, back.size() * 4, back.data());
  EXPECT_EQ(back, std::vector<std::uint32_t>(data.size(), 0));

  gl::Buffer moved = std::move(buffer);
  EXPECT_EQ(buffer.id(), 0u);  // NOLINT(bugprone-use-after-move)
  EXPECT_EQ(moved.size(), data.size() * 4);
  EXPECT_ANY_THROW(moved.upload(moved.size() - 4, data.data(), 8)) << "past the end";
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

TEST_F(GlContext, TimerQueryMeasuresADispatch) {
  const gl::Program program = gl::Program::compute(gl::shaderSource("SharedMathTest.comp"));
  struct Params {
    std::uint32_t count;
    float maxJitter;
    std::uint32_t pad[2];
  } params{4096, 0.5f, {0, 0}};
  gl::Buffer paramBuffer(sizeof params, &params);
  const std::vector<std::uint32_t> unset(4096, 0xffffffffu);  // what the dispatch must overwrite
  gl::Buffer inputs(4096 * 16), mortons(4096 * 4, unset.data()), jitters(4096 * 16);
  inputs.clearZero();
  paramBuffer.bindBase(GL_UNIFORM_BUFFER, 0);
  inputs.bindBase(GL_SHADER_STORAGE_BUFFER, 0);
  mortons.bindBase(GL_SHADER_STORAGE_BUFFER, 1);
  jitters.bindBase(GL_SHADER_STORAGE_BUFFER, 2);
  gl::TimerQuery timer;
  EXPECT_ANY_THROW((void)timer.milliseconds()) << "no result before begin()/end()";
  program.use();
  timer.begin();
  program.dispatch(4096 / 64);
  timer.end();
  const double ms = timer.milliseconds();
  EXPECT_GT(ms, 0.0) << "the timer saw no work";
  std::cout << "[          ] dispatch of 4096 invocations: " << ms << " ms\n";
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<std::uint32_t> codes(4096);
  mortons.download(0, codes.size() * 4, codes.data());
  for (std::size_t i = 0; i < codes.size(); ++i)
    ASSERT_EQ(codes[i], flipscope::mortonEncode3(0, 0, 0)) << "invocation " << i << " did not run";
  EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

}  // namespace
