#include "smoothing/GpuScreenDevice.h"

#include "core/Error.h"
#include "gl/ShaderSource.h"

namespace flipscope {

namespace {
// Binding points of smoothing/glsl/ScreenPass.glsl (and ScreenPairPassMain.glsl's second output).
constexpr GLuint kFrameBlock = 0, kPassBlock = 1, kFirstInput = 2, kOutput = 6, kSecondOutput = 7;
constexpr std::uint32_t kGroupSize = 8;     // local_size_x and _y of ScreenPass.glsl
constexpr std::size_t kPassBlockBytes = 1024;  // larger than any pass's parameter struct

gl::Buffer makeBuffer(std::size_t elements) { return gl::Buffer(std::max<std::uint64_t>(elements * 16, 16)); }
}  // namespace

GpuScreenDevice::GpuScreenDevice(std::string name)
    : mName(std::move(name)), mFrameBlock(sizeof(ScreenFrame)), mPassBlock(kPassBlockBytes) {}

GpuScreenDevice::~GpuScreenDevice() = default;

void GpuScreenDevice::setFrame(const ScreenFrame& frame) {
  const bool resized = frame.width != mFrame.width || frame.height != mFrame.height;
  mFrame = frame;
  mFrameBlock.upload(0, &mFrame, sizeof(ScreenFrame));
  if (!resized) return;
  for (Image& image : mImages) {
    if (!image.perPixel) continue;
    image.elements = std::size_t(frame.width) * frame.height * image.perPixel;
    if (!image.adopted) image.owned = makeBuffer(image.elements);
  }
}

ScreenImage GpuScreenDevice::createFrameImage(std::uint32_t perPixel) {
  FLIPSCOPE_CHECK(perPixel > 0);
  Image image;
  image.perPixel = perPixel;
  image.elements = std::size_t(width()) * height() * perPixel;
  image.owned = makeBuffer(image.elements);
  mImages.push_back(std::move(image));
  return ScreenImage(mImages.size() - 1);
}

ScreenImage GpuScreenDevice::createFixedImage(std::size_t elements) {
  Image image;
  image.elements = elements;
  image.owned = makeBuffer(elements);
  mImages.push_back(std::move(image));
  return ScreenImage(mImages.size() - 1);
}

ScreenImage GpuScreenDevice::adoptFrameBuffer(const gl::Buffer* buffer, std::uint32_t perPixel) {
  FLIPSCOPE_CHECK(buffer && perPixel > 0);
  Image image;
  image.perPixel = perPixel;
  image.elements = std::size_t(width()) * height() * perPixel;
  image.adopted = buffer;
  mImages.push_back(std::move(image));
  return ScreenImage(mImages.size() - 1);
}

GpuScreenDevice::Image& GpuScreenDevice::image(ScreenImage handle) {
  FLIPSCOPE_CHECK(handle < mImages.size(), "screen image " << handle);
  return mImages[handle];
}

const gl::Buffer& GpuScreenDevice::buffer(ScreenImage handle) const {
  FLIPSCOPE_CHECK(handle < mImages.size(), "screen image " << handle);
  return mImages[handle].buffer();
}

void GpuScreenDevice::upload(ScreenImage handle, std::span<const glm::vec4> data) {
  Image& target = image(handle);
  FLIPSCOPE_CHECK(!target.adopted && data.size() == target.elements, data.size() << " != " << target.elements);
  if (!data.empty()) target.owned.upload(0, data.data(), data.size_bytes());
}

void GpuScreenDevice::downloadInto(ScreenImage handle, std::vector<glm::vec4>& pixels) {
  const Image& source = image(handle);
  pixels.resize(source.elements);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  if (!pixels.empty()) source.buffer().download(0, pixels.size() * sizeof(glm::vec4), pixels.data());
}

const gl::Program& GpuScreenDevice::program(const ScreenPass& pass) {
  auto key = std::make_pair(std::string(pass.shader), std::string(pass.kernel));
  auto found = mPrograms.find(key);
  if (found != mPrograms.end()) return found->second;
  const std::string defines = "#define FS_KERNEL " + key.second + "\n";
  gl::Program program = gl::Program::compute(gl::shaderSource(pass.shader, defines), key.first + ":" + key.second);
  return mPrograms.emplace(std::move(key), std::move(program)).first->second;
}

void GpuScreenDevice::run(const ScreenPass& pass, const void* params, std::size_t paramBytes,
                          std::initializer_list<ScreenImage> inputs, ScreenImage output) {
  dispatch(pass, params, paramBytes, inputs, {output});
}

void GpuScreenDevice::runPair(const ScreenPass& pass, const void* params, std::size_t paramBytes,
                              std::initializer_list<ScreenImage> inputs, ScreenImage output,
                              ScreenImage secondOutput) {
  FLIPSCOPE_CHECK(output != secondOutput, pass.kernel << ": both outputs are one image");
  dispatch(pass, params, paramBytes, inputs, {output, secondOutput});
}

void GpuScreenDevice::dispatch(const ScreenPass& pass, const void* params, std::size_t paramBytes,
                               std::initializer_list<ScreenImage> inputs, std::initializer_list<ScreenImage> outputs) {
  FLIPSCOPE_CHECK(inputs.size() <= 4 && paramBytes <= kPassBlockBytes, pass.kernel);
  const gl::Program& prog = program(pass);
  if (paramBytes) mPassBlock.upload(0, params, paramBytes);
  mFrameBlock.bindBase(GL_UNIFORM_BUFFER, kFrameBlock);
  mPassBlock.bindBase(GL_UNIFORM_BUFFER, kPassBlock);
  GLuint binding = kFirstInput;
  const gl::Buffer* first = nullptr;
  for (ScreenImage handle : inputs) {
    for (ScreenImage output : outputs) FLIPSCOPE_CHECK(handle != output, pass.kernel << ": an output is also an input");
    const gl::Buffer& buffer = image(handle).buffer();
    if (!first) first = &buffer;
    buffer.bindBase(GL_SHADER_STORAGE_BUFFER, binding++);
  }
  // Unused inputs are bound to a valid buffer (a shader never reads them).
  for (; binding < kOutput; ++binding) (first ? *first : mPassBlock).bindBase(GL_SHADER_STORAGE_BUFFER, binding);
  GLuint outputBinding = kOutput;
  for (ScreenImage output : outputs) {
    Image& target = image(output);
    FLIPSCOPE_CHECK(target.perPixel == 1 && !target.adopted, pass.kernel << ": an output must be an owned frame image");
    target.owned.bindBase(GL_SHADER_STORAGE_BUFFER, outputBinding++);
  }
  prog.use();
  prog.dispatch((width() + kGroupSize - 1) / kGroupSize, (height() + kGroupSize - 1) / kGroupSize, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_UNIFORM_BARRIER_BIT);
}

void GpuScreenDevice::finish() { glFinish(); }

void GpuScreenDevice::clear(ScreenImage handle) {
  Image& target = image(handle);
  FLIPSCOPE_CHECK(!target.adopted, "cannot clear an adopted buffer");
  target.owned.clearZero();
}

void GpuScreenDevice::copy(ScreenImage from, ScreenImage to) {
  const Image& source = image(from);
  Image& target = image(to);
  FLIPSCOPE_CHECK(!target.adopted && source.elements == target.elements, source.elements << " != " << target.elements);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  if (source.elements)
    glCopyNamedBufferSubData(source.buffer().id(), target.owned.id(), 0, 0, GLsizeiptr(source.elements * 16));
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

}  // namespace flipscope
