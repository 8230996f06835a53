// A linked GLSL program built from vertex and fragment source, with the compiler's log in errors.
#pragma once

#include "GlHeaders.h"

#include <weft/Result.h>

#include <string>

namespace weft {

/// Owns one GL program object; needs the context current when built and destroyed.
class ShaderProgram {
 public:
  /// Compiles and links; the error names the stage and carries the driver's log and the
  /// offending source lines, numbered.
  static Result<ShaderProgram> build(const std::string& vertexSource, const std::string& fragmentSource);

  ShaderProgram() = default;
  ShaderProgram(ShaderProgram&& other) noexcept : m_program(other.m_program) { other.m_program = 0; }
  ShaderProgram& operator=(ShaderProgram&& other) noexcept;
  ShaderProgram(const ShaderProgram&) = delete;
  ShaderProgram& operator=(const ShaderProgram&) = delete;
  ~ShaderProgram();

  /// The GL program name (0 when empty).
  GLuint id() const { return m_program; }
  /// Forgets the program without deleting it (when the context can no longer be made current,
  /// the program dies with the context).
  void abandon() { m_program = 0; }
  /// Location of a uniform; -1 (ignored by glUniform*) when the driver optimised it away.
  GLint uniform(const char* name) const { return glGetUniformLocation(m_program, name); }

 private:
  explicit ShaderProgram(GLuint program) : m_program(program) {}
  GLuint m_program = 0;
};

}  // namespace weft
