// Move-only RAII wrappers of the OpenGL 4.5 objects the ray-caster needs (direct state access).
// Every call needs a current context (gl/EglContext.h); destroy the objects before it.
// A default-constructed object is empty (id() == 0) except TimerQuery, which needs no arguments.
// Misuse (out-of-range offsets, calls on empty objects) fails FLIPSCOPE_CHECK.
#pragma once

#include <epoxy/gl.h>

#include <cstdint>
#include <string_view>

namespace flipscope::gl {

/// Immutable-size buffer storage (glNamedBufferStorage with GL_DYNAMIC_STORAGE_BIT |
/// GL_MAP_READ_BIT), usable as SSBO, UBO or anything else bindBase() accepts.
class Buffer {
 public:
  Buffer() = default;
  /// `bytes` > 0; the content is `data` (bytes bytes) or undefined when data is null.
  explicit Buffer(std::uint64_t bytes, const void* data = nullptr);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  /// Writes `bytes` bytes at byte `offset` (offset + bytes <= size()).
  void upload(std::uint64_t offset, const void* data, std::uint64_t bytes);
  /// Reads `bytes` bytes at byte `offset` into `data` (waits for the GPU; issue
  /// glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT) first after shader writes).
  void download(std::uint64_t offset, std::uint64_t bytes, void* data) const;
  /// Sets every byte to zero.
  void clearZero();
  /// Sets `bytes` bytes from byte `offset` to zero (both multiples of 4, within size()).
  void clearZero(std::uint64_t offset, std::uint64_t bytes);
  /// glBindBufferBase(target, index, id()), e.g. GL_SHADER_STORAGE_BUFFER or GL_UNIFORM_BUFFER.
  void bindBase(GLenum target, GLuint index) const;

  std::uint64_t size() const { return mSize; }
  GLuint id() const { return mId; }

 private:
  GLuint mId = 0;
  std::uint64_t mSize = 0;
};

/// GPU time of the commands between begin() and end() (GL_TIME_ELAPSED).
class TimerQuery {
 public:
  TimerQuery();  ///< creates the query object
  ~TimerQuery();
  TimerQuery(TimerQuery&& other) noexcept;
  TimerQuery& operator=(TimerQuery&& other) noexcept;
  TimerQuery(const TimerQuery&) = delete;
  TimerQuery& operator=(const TimerQuery&) = delete;

  void begin();
  void end();
  /// Elapsed time of the last begin()/end() pair in milliseconds; waits for the result.
  double milliseconds() const;
  GLuint id() const { return mId; }

 private:
  GLuint mId = 0;
  bool mEnded = false;
};

/// A linked compute-shader program.
class Program {
 public:
  Program() = default;
  /// Compiles and links `source` (a complete GLSL source, see gl/ShaderSource.h).
  /// Throws std::runtime_error with the info log and the numbered source when that fails;
  /// `name` starts the message.
  static Program compute(std::string_view source, std::string_view name = "compute shader");
  ~Program();
  Program(Program&& other) noexcept;
  Program& operator=(Program&& other) noexcept;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  /// glUseProgram(id()).
  void use() const;
  /// glDispatchCompute on the program in use (call use() first); the caller issues barriers.
  void dispatch(std::uint32_t groupsX, std::uint32_t groupsY = 1, std::uint32_t groupsZ = 1) const;
  GLuint id() const { return mId; }

 private:
  explicit Program(GLuint id) : mId(id) {}
  GLuint mId = 0;
};

}  // namespace flipscope::gl
