// ClothRenderer: see the design note in ClothRenderer.h.
//
// Frame order: validate (nothing touched on error) → clock starts → convert cloths to float into
// the reused CPU buffers → glBufferSubData → clear → shaded cloth (polygon offset when a wireframe
// follows) → wireframe → colliders → glFinish → clock → optional readback → clock.
#include "EglContextImpl.h"
#include "GlHeaders.h"
#include "PrimitiveMesh.h"
#include "RenderMath.h"
#include "ShaderProgram.h"

#include <weft/render/ClothRenderer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <vector>

namespace weft {
namespace {

constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_viewProjection;
uniform mat4 u_model;
uniform mat3 u_normalMatrix;
out vec3 v_normal;
void main() {
  v_normal = u_normalMatrix * a_normal;
  gl_Position = u_viewProjection * (u_model * vec4(a_position, 1.0));
}
)";

// Two-sided Lambert + ambient. Back faces flip the normal and take their own colour. A zero normal
// (a vertex of degenerate triangles only) shades with ambient light instead of NaN.
constexpr const char* kFragmentShader = R"(#version 330 core
in vec3 v_normal;
uniform vec3 u_lightDirection;
uniform vec3 u_frontColor;
uniform vec3 u_backColor;
uniform float u_ambient;
uniform bool u_unlit;
out vec4 fragColor;
void main() {
  if (u_unlit) {
    fragColor = vec4(u_frontColor, 1.0);
    return;
  }
  float len = length(v_normal);
  vec3 n = len > 1e-12 ? v_normal / len : vec3(0.0);
  vec3 base = u_frontColor;
  if (!gl_FrontFacing) {
    n = -n;
    base = u_backColor;
  }
  float diffuse = max(dot(n, u_lightDirection), 0.0);
  fragColor = vec4(base * (u_ambient + (1.0 - u_ambient) * diffuse), 1.0);
}
)";

constexpr GLsizei kVertexStride = PrimitiveMesh::kFloatsPerVertex * sizeof(float);
// Buffers grow by half again when too small, so a slowly growing scene reallocates rarely.
constexpr double kBufferGrowth = 1.5;
// Depth offset of the shaded cloth under a wireframe, in GL's (factor, units): one depth-slope and
// one depth-resolution step is enough for lines drawn over the same triangles.
constexpr GLfloat kWireframeOffsetFactor = 1.0f;
constexpr GLfloat kWireframeOffsetUnits = 1.0f;

using Clock = std::chrono::steady_clock;

double millisecondsBetween(Clock::time_point begin, Clock::time_point end) {
  return std::chrono::duration<double, std::milli>(end - begin).count();
}

Eigen::Matrix4f toFloat(const Mat4& m) { return m.cast<float>(); }

std::string sizeText(std::size_t n) { return std::to_string(n); }

/// A VAO with its own vertex and index buffers, laid out as PrimitiveMesh.
struct GpuMesh {
  GLuint vertexArray = 0;
  GLuint vertexBuffer = 0;
  GLuint indexBuffer = 0;
  GLsizei indexCount = 0;
  std::size_t vertexCapacityBytes = 0;
  std::size_t indexCapacityBytes = 0;

  void create() {
    glGenVertexArrays(1, &vertexArray);
    glGenBuffers(1, &vertexBuffer);
    glGenBuffers(1, &indexBuffer);
    glBindVertexArray(vertexArray);
    glBindBuffer(GL_ARRAY_BUFFER, vertexBuffer);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, indexBuffer);  // recorded in the VAO
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, kVertexStride, nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, kVertexStride, reinterpret_cast<const void*>(3 * sizeof(float)));
    glBindVertexArray(0);
  }

  // Uploads with glBufferSubData, growing a buffer with glBufferData only when it is too small.
  void upload(const std::vector<float>& vertices, const std::vector<std::uint32_t>& indices) {
    glBindVertexArray(vertexArray);
    const std::size_t vertexBytes = vertices.size() * sizeof(float);
    const std::size_t indexBytes = indices.size() * sizeof(std::uint32_t);
    glBindBuffer(GL_ARRAY_BUFFER, vertexBuffer);
    if (vertexBytes > vertexCapacityBytes) {
      vertexCapacityBytes = static_cast<std::size_t>(static_cast<double>(vertexBytes) * kBufferGrowth);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertexCapacityBytes), nullptr, GL_DYNAMIC_DRAW);
    }
    if (vertexBytes > 0) glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(vertexBytes), vertices.data());
    if (indexBytes > indexCapacityBytes) {
      indexCapacityBytes = static_cast<std::size_t>(static_cast<double>(indexBytes) * kBufferGrowth);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indexCapacityBytes), nullptr, GL_DYNAMIC_DRAW);
    }
    if (indexBytes > 0) glBufferSubData(GL_ELEMENT_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(indexBytes), indices.data());
    indexCount = static_cast<GLsizei>(indices.size());
    glBindVertexArray(0);
  }

  void uploadStatic(const PrimitiveMesh& mesh) {
    create();
    glBindVertexArray(vertexArray);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.vertices.size() * sizeof(float)), mesh.vertices.data(),
                 GL_STATIC_DRAW);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.indices.size() * sizeof(std::uint32_t)),
                 mesh.indices.data(), GL_STATIC_DRAW);
    indexCount = static_cast<GLsizei>(mesh.indices.size());
    glBindVertexArray(0);
  }

  void draw() const {
    if (indexCount == 0) return;
    glBindVertexArray(vertexArray);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
  }

  void destroy() {
    if (vertexArray != 0) glDeleteVertexArrays(1, &vertexArray);
    const GLuint buffers[] = {vertexBuffer, indexBuffer};
    glDeleteBuffers(2, buffers);
    *this = {};
  }
};

Status validateSettings(const RenderSettings& s) {
  const CameraSettings& c = s.camera;
  if (s.width <= 0 || s.height <= 0) {
    return Error{"RenderSettings: width and height must be positive pixels (got " + std::to_string(s.width) + "x" +
                 std::to_string(s.height) + ")"};
  }
  if (!isFinite(c.eye) || !isFinite(c.target) || !isFinite(c.up)) {
    return Error{"RenderSettings::camera: eye, target and up must be finite"};
  }
  if ((c.target - c.eye).squaredNorm() == 0) {
    return Error{"RenderSettings::camera: eye and target are the same point; move the eye back from the target"};
  }
  if (!(c.verticalFovDegrees > 0 && c.verticalFovDegrees < 180)) {
    return Error{"RenderSettings::camera: verticalFovDegrees must be in (0, 180) degrees (got " +
                 std::to_string(c.verticalFovDegrees) + ")"};
  }
  if (!(c.nearDistance > 0 && c.farDistance > c.nearDistance && std::isfinite(c.farDistance))) {
    return Error{"RenderSettings::camera: need 0 < nearDistance < farDistance (got " + std::to_string(c.nearDistance) +
                 " m, " + std::to_string(c.farDistance) + " m)"};
  }
  if (!(s.ambient >= 0 && s.ambient <= 1)) {
    return Error{"RenderSettings: ambient must be in [0, 1] (got " + std::to_string(s.ambient) + ")"};
  }
  if (!isFinite(s.lightDirection) || s.lightDirection.squaredNorm() == 0) {
    return Error{"RenderSettings: lightDirection must be a finite, non-zero vector"};
  }
  return {};
}

Status validateScene(const RenderScene& scene) {
  std::size_t totalVertices = 0;
  for (std::size_t c = 0; c < scene.cloths.size(); ++c) {
    const ClothRenderView& view = scene.cloths[c];
    const std::string name = "cloth " + sizeText(c);
    if (view.indices.size() % 3 != 0) {
      return Error{name + ": " + sizeText(view.indices.size()) + " indices; need three per triangle"};
    }
    if (!view.normals.empty() && view.normals.size() != view.positions.size()) {
      return Error{name + ": " + sizeText(view.positions.size()) + " positions but " + sizeText(view.normals.size()) +
                   " normals; give one normal per vertex, or none to have them computed"};
    }
    for (std::size_t i = 0; i < view.indices.size(); ++i) {
      if (view.indices[i] >= view.positions.size()) {
        return Error{name + ": triangle " + sizeText(i / 3) + " uses vertex " + std::to_string(view.indices[i]) +
                     " but the cloth has " + sizeText(view.positions.size()) + " vertices"};
      }
    }
    totalVertices += view.positions.size();
  }
  if (totalVertices > std::numeric_limits<std::uint32_t>::max()) {
    return Error{"RenderScene: more than 2^32 vertices in one frame; draw the cloths in several frames"};
  }
  for (std::size_t i = 0; i < scene.colliders.size(); ++i) {
    const Real radius = std::visit(
        [](const auto& p) -> Real {
          using T = std::decay_t<decltype(p)>;
          if constexpr (std::is_same_v<T, SpherePrimitive> || std::is_same_v<T, CapsulePrimitive>) return p.radius;
          else if constexpr (std::is_same_v<T, PlanePrimitive>) return p.halfSize;
          else return p.halfExtents.minCoeff();
        },
        scene.colliders[i]);
    if (!(radius >= 0) || !std::isfinite(radius)) {
      return Error{"collider " + sizeText(i) + ": radius, halfSize and halfExtents must be finite and ≥ 0 m"};
    }
  }
  return {};
}

}  // namespace

class ClothRenderer::Impl {
 public:
  EglContext::Impl* context = nullptr;
  RenderSettings settings;
  ShaderProgram program;
  GLint uViewProjection = -1, uModel = -1, uNormalMatrix = -1, uLightDirection = -1;
  GLint uFrontColor = -1, uBackColor = -1, uAmbient = -1, uUnlit = -1;
  GpuMesh cloth, sphere, cylinder, quad, cube;
  // CPU staging kept between frames: a steady frame allocates nothing.
  std::vector<float> vertexData;
  std::vector<std::uint32_t> indexData;
  std::vector<Vec3> normalScratch;
  FrameTiming lastTiming;

  ~Impl() {
    if (context == nullptr) return;
    if (!context->makeCurrent()) {
      program.abandon();  // freed with the context
      return;
    }
    for (GpuMesh* mesh : {&cloth, &sphere, &cylinder, &quad, &cube}) mesh->destroy();
  }

  Status initialise() {
    if (Status status = context->makeCurrent(); !status) return status;
    Result<ShaderProgram> built = ShaderProgram::build(kVertexShader, kFragmentShader);
    if (!built) return built.error();
    program = std::move(built).value();
    uViewProjection = program.uniform("u_viewProjection");
    uModel = program.uniform("u_model");
    uNormalMatrix = program.uniform("u_normalMatrix");
    uLightDirection = program.uniform("u_lightDirection");
    uFrontColor = program.uniform("u_frontColor");
    uBackColor = program.uniform("u_backColor");
    uAmbient = program.uniform("u_ambient");
    uUnlit = program.uniform("u_unlit");
    cloth.create();
    sphere.uploadStatic(makeSphereMesh());
    cylinder.uploadStatic(makeCylinderMesh());
    quad.uploadStatic(makeQuadMesh());
    cube.uploadStatic(makeCubeMesh());
    if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
      return Error{"OpenGL error " + std::to_string(error) + " while building the renderer's buffers"};
    }
    return {};
  }

  // Concatenates every cloth into vertexData/indexData (float position + normal, shifted indices).
  void stageCloths(std::span<const ClothRenderView> cloths) {
    std::size_t vertexCount = 0, indexCount = 0;
    for (const ClothRenderView& view : cloths) {
      vertexCount += view.positions.size();
      indexCount += view.indices.size();
    }
    vertexData.resize(vertexCount * PrimitiveMesh::kFloatsPerVertex);
    indexData.resize(indexCount);
    float* vertexOut = vertexData.data();
    std::uint32_t* indexOut = indexData.data();
    std::uint32_t base = 0;
    for (const ClothRenderView& view : cloths) {
      std::span<const Vec3> normals = view.normals;
      if (normals.empty()) {
        computeAreaWeightedNormals(view.positions, view.indices, normalScratch);
        normals = normalScratch;
      }
      for (std::size_t v = 0; v < view.positions.size(); ++v) {
        const Vec3& p = view.positions[v];
        const Vec3& n = normals[v];
        *vertexOut++ = static_cast<float>(p.x());
        *vertexOut++ = static_cast<float>(p.y());
        *vertexOut++ = static_cast<float>(p.z());
        *vertexOut++ = static_cast<float>(n.x());
        *vertexOut++ = static_cast<float>(n.y());
        *vertexOut++ = static_cast<float>(n.z());
      }
      for (Index i : view.indices) *indexOut++ = base + i;
      base += static_cast<std::uint32_t>(view.positions.size());
    }
  }

  void setModel(const Mat4& model) {
    const Eigen::Matrix4f m = toFloat(model);
    // Normals transform with the inverse transpose (non-uniform scale of boxes and cylinders);
    // a zero scale (degenerate primitive) would not invert, so fall back to the plain matrix.
    const Mat3 linear = model.block<3, 3>(0, 0);
    const Mat3 normalMatrix = std::abs(linear.determinant()) > 1e-30 ? Mat3(linear.inverse().transpose()) : linear;
    const Eigen::Matrix3f n = normalMatrix.cast<float>();
    glUniformMatrix4fv(uModel, 1, GL_FALSE, m.data());
    glUniformMatrix3fv(uNormalMatrix, 1, GL_FALSE, n.data());
  }

  void setColors(const ColorRgb& front, const ColorRgb& back) {
    glUniform3f(uFrontColor, front.r, front.g, front.b);
    glUniform3f(uBackColor, back.r, back.g, back.b);
  }

  // Model matrix mapping local axes (columns of basis, already scaled) to world, then translating.
  static Mat4 placement(const Mat3& basis, const Vec3& origin) {
    Mat4 model = Mat4::Identity();
    model.block<3, 3>(0, 0) = basis;
    model.block<3, 1>(0, 3) = origin;
    return model;
  }

  void drawSphere(const Vec3& center, Real radius, const ColorRgb& color) {
    setColors(color, color);
    setModel(placement(Mat3::Identity() * radius, center));
    sphere.draw();
  }

  void drawCollider(const ColliderPrimitive& primitive) {
    if (const auto* s = std::get_if<SpherePrimitive>(&primitive)) {
      drawSphere(s->center, s->radius, s->color);
    } else if (const auto* p = std::get_if<PlanePrimitive>(&primitive)) {
      // Quad axes (t1, n, t2) right-handed so the quad's +y face becomes the plane's normal side.
      const Vec3 n = p->normal.squaredNorm() > 0 ? Vec3(p->normal.normalized()) : Vec3::UnitY();
      const Vec3 t1 = anyPerpendicular(n);
      const Vec3 t2 = t1.cross(n);
      Mat3 basis;
      basis << t1 * p->halfSize, n, t2 * p->halfSize;
      setColors(p->color, p->color);
      setModel(placement(basis, p->point));
      quad.draw();
    } else if (const auto* c = std::get_if<CapsulePrimitive>(&primitive)) {
      const Vec3 axis = c->b - c->a;
      const Real length = axis.norm();
      if (length > 0) {
        const Vec3 dir = axis / length;
        const Vec3 u = anyPerpendicular(dir);
        const Vec3 w = u.cross(dir);  // (u, dir, w) right-handed like (x, y, z)
        Mat3 basis;
        basis << u * c->radius, axis, w * c->radius;
        setColors(c->color, c->color);
        setModel(placement(basis, c->a));
        cylinder.draw();
      }
      drawSphere(c->a, c->radius, c->color);
      drawSphere(c->b, c->radius, c->color);
    } else if (const auto* b = std::get_if<BoxPrimitive>(&primitive)) {
      setColors(b->color, b->color);
      setModel(placement(b->rotation * b->halfExtents.asDiagonal(), b->center));
      cube.draw();
    }
  }

  Result<FrameTiming> render(const RenderScene& scene, Image* image) {
    if (Status status = validateScene(scene); !status) return status.error();
    const Clock::time_point start = Clock::now();
    if (Status status = context->makeCurrent(); !status) return status.error();
    if (settings.width != context->width || settings.height != context->height) {
      if (Status status = context->allocateFramebuffer(settings.width, settings.height); !status) return status.error();
    }
    context->bind();

    stageCloths(scene.cloths);
    cloth.upload(vertexData, indexData);

    const ColorRgb& bg = settings.background;
    glClearColor(bg.r, bg.g, bg.b, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDisable(GL_CULL_FACE);  // two-sided: cloth is seen from both sides
    glDisable(GL_BLEND);

    const CameraSettings& camera = settings.camera;
    const Mat4 view = lookAtMatrix(camera.eye, camera.target, camera.up);
    const Real aspect = static_cast<Real>(settings.width) / static_cast<Real>(settings.height);
    const Mat4 projection = perspectiveMatrix(camera.verticalFovDegrees, aspect, camera.nearDistance, camera.farDistance);
    const Eigen::Matrix4f viewProjection = toFloat(projection * view);
    Vec3 light = settings.lightDirection.normalized();
    if (settings.lightFollowsCamera) {
      // View rotation rows are the camera axes, so its transpose takes camera space to world.
      light = view.block<3, 3>(0, 0).transpose() * light;
    }

    glUseProgram(program.id());
    glUniformMatrix4fv(uViewProjection, 1, GL_FALSE, viewProjection.data());
    glUniform3f(uLightDirection, static_cast<float>(light.x()), static_cast<float>(light.y()),
                static_cast<float>(light.z()));
    glUniform1f(uAmbient, settings.ambient);
    glUniform1i(uUnlit, 0);

    // Shaded cloth, pushed back in depth when the wireframe is drawn over it.
    setModel(Mat4::Identity());
    setColors(settings.clothFront, settings.clothBack);
    if (settings.wireframe) {
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(kWireframeOffsetFactor, kWireframeOffsetUnits);
    }
    cloth.draw();
    glDisable(GL_POLYGON_OFFSET_FILL);

    if (settings.wireframe) {
      glUniform1i(uUnlit, 1);
      setColors(settings.wireframeColor, settings.wireframeColor);
      glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
      cloth.draw();
      glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
      glUniform1i(uUnlit, 0);
    }

    if (settings.drawColliders) {
      for (const ColliderPrimitive& primitive : scene.colliders) drawCollider(primitive);
    }
    glBindVertexArray(0);
    glFinish();  // the rasteriser's work belongs to render time, not to readback
    const Clock::time_point drawn = Clock::now();

    FrameTiming timing;
    timing.renderMs = millisecondsBetween(start, drawn);
    if (image != nullptr) {
      context->readPixels(*image);
      timing.readbackMs = millisecondsBetween(drawn, Clock::now());
    }
    if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
      std::ostringstream message;
      message << "OpenGL error 0x" << std::hex << error << " while rendering a frame; run with a debug context "
              << "(ContextSettings::debugContext) to locate it";
      return Error{message.str()};
    }
    lastTiming = timing;
    return timing;
  }
};

Result<ClothRenderer> ClothRenderer::create(EglContext& context, const RenderSettings& settings) {
  if (Status status = validateSettings(settings); !status) return status.error();
  auto impl = std::make_unique<Impl>();
  impl->context = context.m_impl.get();
  impl->settings = settings;
  if (Status status = impl->initialise(); !status) return status.error();
  return ClothRenderer(std::move(impl));
}

ClothRenderer::ClothRenderer(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
ClothRenderer::ClothRenderer(ClothRenderer&&) noexcept = default;
ClothRenderer& ClothRenderer::operator=(ClothRenderer&&) noexcept = default;
ClothRenderer::~ClothRenderer() = default;

Status ClothRenderer::setSettings(const RenderSettings& settings) {
  if (Status status = validateSettings(settings); !status) return status;
  m_impl->settings = settings;
  return {};
}

const RenderSettings& ClothRenderer::settings() const { return m_impl->settings; }

Result<FrameTiming> ClothRenderer::renderFrame(const RenderScene& scene) { return m_impl->render(scene, nullptr); }

Result<FrameTiming> ClothRenderer::renderFrame(const RenderScene& scene, Image& image) {
  return m_impl->render(scene, &image);
}

const FrameTiming& ClothRenderer::lastTiming() const { return m_impl->lastTiming; }

}  // namespace weft
