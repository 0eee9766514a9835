#include "gl/Objects.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/Error.h"

namespace flipscope::gl {

namespace {

constexpr std::uint64_t kMaxGlSize = std::uint64_t(std::numeric_limits<GLsizeiptr>::max());

/// The source with each line prefixed by its number (as in the compiler's messages, from 1).
std::string numberedSource(std::string_view source) {
  std::string out;
  int line = 1;
  std::size_t start = 0;
  while (start <= source.size()) {
    std::size_t end = source.find('\n', start);
    if (end == std::string_view::npos) end = source.size();
    if (end == source.size() && start == end) break;  // no empty line after a final newline
    char number[16];
    std::snprintf(number, sizeof number, "%5d| ", line++);
    out += number;
    out.append(source.substr(start, end - start));
    out += '\n';
    start = end + 1;
  }
  return out;
}

/// The info log of a shader or program, through its glGet*iv and glGet*InfoLog pair.
template <class GetIv, class GetLog>
std::string infoLog(GLuint object, GetIv getIv, GetLog getLog) {
  GLint length = 0;
  getIv(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(std::size_t(std::max(length, 1)), '\0');
  getLog(object, GLsizei(log.size()), nullptr, log.data());
  log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
  return log;
}

std::string shaderLog(GLuint shader) { return infoLog(shader, glGetShaderiv, glGetShaderInfoLog); }
std::string programLog(GLuint program) { return infoLog(program, glGetProgramiv, glGetProgramInfoLog); }

}  // namespace

// ---- Buffer ----

Buffer::Buffer(std::uint64_t bytes, const void* data) : mSize(bytes) {
  FLIPSCOPE_CHECK(bytes > 0 && bytes <= kMaxGlSize, "bytes=" << bytes);
  glCreateBuffers(1, &mId);
  glNamedBufferStorage(mId, GLsizeiptr(bytes), data, GL_DYNAMIC_STORAGE_BIT | GL_MAP_READ_BIT);
}

Buffer::~Buffer() {
  if (mId) glDeleteBuffers(1, &mId);
}

Buffer::Buffer(Buffer&& other) noexcept : mId(std::exchange(other.mId, 0)), mSize(std::exchange(other.mSize, 0)) {}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    if (mId) glDeleteBuffers(1, &mId);
    mId = std::exchange(other.mId, 0);
    mSize = std::exchange(other.mSize, 0);
  }
  return *this;
}

void Buffer::upload(std::uint64_t offset, const void* data, std::uint64_t bytes) {
  FLIPSCOPE_CHECK(mId != 0 && offset <= mSize && bytes <= mSize - offset,
                  "offset=" << offset << " bytes=" << bytes << " size=" << mSize);
  if (bytes) glNamedBufferSubData(mId, GLintptr(offset), GLsizeiptr(bytes), data);
}

void Buffer::download(std::uint64_t offset, std::uint64_t bytes, void* data) const {
  FLIPSCOPE_CHECK(mId != 0 && offset <= mSize && bytes <= mSize - offset,
                  "offset=" << offset << " bytes=" << bytes << " size=" << mSize);
  if (bytes) glGetNamedBufferSubData(mId, GLintptr(offset), GLsizeiptr(bytes), data);
}

void Buffer::clearZero() {
  FLIPSCOPE_CHECK(mId != 0);
  glClearNamedBufferData(mId, GL_R8UI, GL_RED_INTEGER, GL_UNSIGNED_BYTE, nullptr);  // null data: zeros
}

void Buffer::clearZero(std::uint64_t offset, std::uint64_t bytes) {
  FLIPSCOPE_CHECK(mId != 0 && offset + bytes <= mSize && offset % 4 == 0 && bytes % 4 == 0);
  glClearNamedBufferSubData(mId, GL_R32UI, GLintptr(offset), GLsizeiptr(bytes), GL_RED_INTEGER, GL_UNSIGNED_INT,
                            nullptr);
}

void Buffer::bindBase(GLenum target, GLuint index) const {
  FLIPSCOPE_CHECK(mId != 0, "binding an empty buffer at " << index);
  glBindBufferBase(target, index, mId);
}

// ---- TimerQuery ----

TimerQuery::TimerQuery() { glCreateQueries(GL_TIME_ELAPSED, 1, &mId); }

TimerQuery::~TimerQuery() {
  if (mId) glDeleteQueries(1, &mId);
}

TimerQuery::TimerQuery(TimerQuery&& other) noexcept
    : mId(std::exchange(other.mId, 0)), mEnded(std::exchange(other.mEnded, false)) {}

TimerQuery& TimerQuery::operator=(TimerQuery&& other) noexcept {
  if (this != &other) {
    if (mId) glDeleteQueries(1, &mId);
    mId = std::exchange(other.mId, 0);
    mEnded = std::exchange(other.mEnded, false);
  }
  return *this;
}

void TimerQuery::begin() {
  FLIPSCOPE_CHECK(mId != 0);
  glBeginQuery(GL_TIME_ELAPSED, mId);
}

void TimerQuery::end() {
  FLIPSCOPE_CHECK(mId != 0);
  glEndQuery(GL_TIME_ELAPSED);
  mEnded = true;
}

double TimerQuery::milliseconds() const {
  FLIPSCOPE_CHECK(mId != 0 && mEnded, "milliseconds() before begin()/end()");
  GLuint64 nanoseconds = 0;
  glGetQueryObjectui64v(mId, GL_QUERY_RESULT, &nanoseconds);
  return double(nanoseconds) * 1e-6;
}

// ---- Program ----

Program Program::compute(std::string_view source, std::string_view name) {
  FLIPSCOPE_CHECK(source.size() <= std::size_t(std::numeric_limits<GLint>::max()));
  const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  const GLchar* text = source.data();
  const GLint length = GLint(source.size());
  glShaderSource(shader, 1, &text, &length);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    const std::string log = shaderLog(shader);
    glDeleteShader(shader);
    throw std::runtime_error(std::string(name) + ": compilation failed:\n" + log + "\nsource:\n" +
                             numberedSource(source));
  }
  Program program(glCreateProgram());
  glAttachShader(program.mId, shader);
  glLinkProgram(program.mId);
  glDetachShader(program.mId, shader);
  glDeleteShader(shader);
  glGetProgramiv(program.mId, GL_LINK_STATUS, &ok);
  if (!ok)
    throw std::runtime_error(std::string(name) + ": linking failed:\n" + programLog(program.mId) + "\nsource:\n" +
                             numberedSource(source));
  return program;
}

Program::~Program() {
  if (mId) glDeleteProgram(mId);
}

Program::Program(Program&& other) noexcept : mId(std::exchange(other.mId, 0)) {}

Program& Program::operator=(Program&& other) noexcept {
  if (this != &other) {
    if (mId) glDeleteProgram(mId);
    mId = std::exchange(other.mId, 0);
  }
  return *this;
}

void Program::use() const {
  FLIPSCOPE_CHECK(mId != 0);
  glUseProgram(mId);
}

void Program::dispatch(std::uint32_t groupsX, std::uint32_t groupsY, std::uint32_t groupsZ) const {
  FLIPSCOPE_CHECK(mId != 0);
  glDispatchCompute(groupsX, groupsY, groupsZ);
}

}  // namespace flipscope::gl
