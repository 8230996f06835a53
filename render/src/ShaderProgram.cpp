#include "ShaderProgram.h"

#include <algorithm>
#include <sstream>
#include <utility>

namespace weft {
namespace {

std::string numbered(const std::string& source) {
  std::istringstream in(source);
  std::ostringstream out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) out << "  " << number << ": " << line << "\n";
  return out.str();
}

std::string shaderLog(GLuint shader) {
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
  glGetShaderInfoLog(shader, length, nullptr, log.data());
  log.resize(std::char_traits<char>::length(log.c_str()));
  return log;
}

Result<GLuint> compile(GLenum stage, const std::string& source, const char* stageName) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    std::string message = std::string(stageName) + " shader failed to compile:\n" + shaderLog(shader) +
                          "source:\n" + numbered(source);
    glDeleteShader(shader);
    return Error{std::move(message)};
  }
  return shader;
}

}  // namespace

Result<ShaderProgram> ShaderProgram::build(const std::string& vertexSource, const std::string& fragmentSource) {
  Result<GLuint> vertex = compile(GL_VERTEX_SHADER, vertexSource, "vertex");
  if (!vertex) return vertex.error();
  Result<GLuint> fragment = compile(GL_FRAGMENT_SHADER, fragmentSource, "fragment");
  if (!fragment) {
    glDeleteShader(vertex.value());
    return fragment.error();
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, vertex.value());
  glAttachShader(program, fragment.value());
  glLinkProgram(program);
  // Shaders are flagged for deletion now and freed with the program.
  glDeleteShader(vertex.value());
  glDeleteShader(fragment.value());
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    log.resize(std::char_traits<char>::length(log.c_str()));
    glDeleteProgram(program);
    return Error{"shader program failed to link:\n" + log};
  }
  return ShaderProgram(program);
}

ShaderProgram& ShaderProgram::operator=(ShaderProgram&& other) noexcept {
  if (this != &other) {
    if (m_program != 0) glDeleteProgram(m_program);
    m_program = std::exchange(other.m_program, 0);
  }
  return *this;
}

ShaderProgram::~ShaderProgram() {
  if (m_program != 0) glDeleteProgram(m_program);
}

}  // namespace weft
