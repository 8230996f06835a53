// Scene file parsing: JSON (nlohmann-json) → SceneDescription, with every problem reported at its
// JSON Pointer path. See SceneFile.h for the design and scenes/data/README.md for the format.
//
// The reader never asks nlohmann for a value of the wrong type (that would throw): every access
// checks the type first and records an issue instead. Numbers are range-checked as doubles before
// they are converted to integers, so no file can cause an out-of-range conversion.
#include <weft/scenes/SceneFile.h>

#include <weft/engine/FabricPresets.h>
#include <weft/engine/InputFile.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <set>
#include <sstream>

namespace weft {
namespace {

using Json = nlohmann::json;

constexpr Real kPi = 3.14159265358979323846;

// Escapes a key for a JSON Pointer (RFC 6901): '~' → "~0", '/' → "~1".
std::string pointerToken(std::string_view key) {
  std::string token;
  for (char c : key) {
    if (c == '~') token += "~0";
    else if (c == '/') token += "~1";
    else token += c;
  }
  return token;
}

std::string child(const std::string& path, std::string_view key) { return path + "/" + pointerToken(key); }
std::string child(const std::string& path, std::size_t index) { return path + "/" + std::to_string(index); }

std::string typeName(const Json& value) {
  switch (value.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::object: return "an object";
    case Json::value_t::array: return "an array";
    case Json::value_t::string: return "a string";
    case Json::value_t::boolean: return "a boolean";
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return "a number";
    default: return "an unsupported value";
  }
}

std::string formatNumber(Real value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

// What a number must satisfy.
enum class Range { Any, Positive, NonNegative };

// Collects issues while walking the document.
class Reader {
 public:
  Reader(const SceneLoadOptions& options, std::vector<SceneIssue>& issues)
      : m_options(options), m_issues(issues) {}

  const SceneLoadOptions& options() const { return m_options; }

  void fail(const std::string& path, std::string message) {
    if (m_issues.size() < m_options.maxIssues) m_issues.push_back({path, std::move(message)});
  }
  bool full() const { return m_issues.size() >= m_options.maxIssues; }
  std::size_t issueCount() const { return m_issues.size(); }

  // Reports `key` of `object`, a key the format no longer has, with what replaced it.
  void removedKey(const Json& object, const std::string& path, const char* key, const char* why) {
    if (object.is_object() && object.contains(key)) {
      fail(child(path, key), std::string("\"") + key + "\" no longer exists: " + why);
    }
  }

  // Reports keys of `object` that are not in `allowed`.
  void checkKeys(const Json& object, const std::string& path,
                 std::initializer_list<std::string_view> allowed) {
    for (const auto& [key, value] : object.items()) {
      if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
      std::string list;
      for (std::string_view name : allowed) list += (list.empty() ? "" : ", ") + std::string(name);
      fail(child(path, key), "unknown key \"" + key + "\"; allowed here: " + list);
    }
  }

  // The member `key` of `object`, or null when absent.
  static const Json* member(const Json& object, std::string_view key) {
    const auto found = object.find(key);
    return found == object.end() ? nullptr : &*found;
  }

  // An object at `path`; false (with an issue) when `value` is something else.
  bool expectObject(const Json& value, const std::string& path, std::string_view what) {
    if (value.is_object()) return true;
    fail(path, "must be an object (" + std::string(what) + "), not " + typeName(value));
    return false;
  }

  // Reads an optional number; keeps `out` when absent. False when present and invalid.
  bool readReal(const Json& object, const std::string& path, std::string_view key, Real& out,
                Range range, std::string_view unit) {
    const Json* value = member(object, key);
    if (!value) return true;
    return realValue(*value, child(path, key), out, range, unit);
  }

  bool realValue(const Json& value, const std::string& path, Real& out, Range range,
                 std::string_view unit) {
    const std::string units = unit.empty() ? "" : " (" + std::string(unit) + ")";
    if (!value.is_number()) {
      fail(path, "must be a number" + units + ", not " + typeName(value));
      return false;
    }
    const Real number = value.get<Real>();
    if (!std::isfinite(number)) {
      fail(path, "must be a finite number" + units);
      return false;
    }
    if (range == Range::Positive && !(number > 0)) {
      fail(path, "is " + formatNumber(number) + " but must be greater than 0" + units);
      return false;
    }
    if (range == Range::NonNegative && number < 0) {
      fail(path, "is " + formatNumber(number) + " but must not be negative" + units);
      return false;
    }
    out = number;
    return true;
  }

  // Reads an optional whole number in [minimum, maximum]; keeps `out` when absent.
  template <typename Integer>
  bool readInteger(const Json& object, const std::string& path, std::string_view key,
                   Integer& out, double minimum, double maximum) {
    const Json* value = member(object, key);
    if (!value) return true;
    return integerValue(*value, child(path, key), out, minimum, maximum);
  }

  template <typename Integer>
  bool integerValue(const Json& value, const std::string& path, Integer& out, double minimum,
                    double maximum) {
    const std::string range = "from " + formatNumber(minimum) + " to " + formatNumber(maximum);
    if (!value.is_number()) {
      fail(path, "must be a whole number " + range + ", not " + typeName(value));
      return false;
    }
    const double number = value.get<double>();
    if (!std::isfinite(number) || number != std::floor(number)) {
      fail(path, "must be a whole number " + range + ", not " + formatNumber(number));
      return false;
    }
    if (number < minimum || number > maximum) {
      fail(path, "is " + formatNumber(number) + ", out of range: give a whole number " + range);
      return false;
    }
    out = static_cast<Integer>(number);
    return true;
  }

  bool readBool(const Json& object, const std::string& path, std::string_view key, bool& out) {
    const Json* value = member(object, key);
    if (!value) return true;
    if (!value->is_boolean()) {
      fail(child(path, key), "must be true or false, not " + typeName(*value));
      return false;
    }
    out = value->get<bool>();
    return true;
  }

  bool readString(const Json& object, const std::string& path, std::string_view key,
                  std::string& out) {
    const Json* value = member(object, key);
    if (!value) return true;
    if (!value->is_string()) {
      fail(child(path, key), "must be a string, not " + typeName(*value));
      return false;
    }
    out = value->get<std::string>();
    return true;
  }

  // The "time" of keyframe `index` of a track: required, in seconds, ≥ 0 and later than the
  // previous keyframe's.
  void readKeyframeTime(const Json& key, const std::string& path, std::size_t index,
                        Real previous, Real& time) {
    if (!member(key, "time")) {
      fail(child(path, "time"), "is missing; give the time in seconds");
      return;
    }
    if (readReal(key, path, "time", time, Range::NonNegative, "s") && index > 0 && !(time > previous)) {
      fail(child(path, "time"), "is " + formatNumber(time) +
                                    " s; keyframe times must increase (the previous is " +
                                    formatNumber(previous) + " s)");
    }
  }

  // Reads an optional [x, y, z]; keeps `out` when absent.
  bool readVec3(const Json& object, const std::string& path, std::string_view key, Vec3& out,
                std::string_view unit, bool nonZero = false) {
    const Json* value = member(object, key);
    if (!value) return true;
    return vec3Value(*value, child(path, key), out, unit, nonZero);
  }

  bool vec3Value(const Json& value, const std::string& path, Vec3& out, std::string_view unit,
                 bool nonZero = false) {
    const std::string units = unit.empty() ? "" : " in " + std::string(unit);
    if (!value.is_array() || value.size() != 3) {
      fail(path, "must be an array of three numbers [x, y, z]" + units + ", not " +
                     (value.is_array() ? "an array of " + std::to_string(value.size())
                                       : typeName(value)));
      return false;
    }
    Vec3 result;
    bool ok = true;
    for (int k = 0; k < 3; ++k) ok = realValue(value[k], child(path, std::size_t(k)), result[k], Range::Any, unit) && ok;
    if (!ok) return false;
    if (nonZero && result.norm() == 0) {
      fail(path, "must not be the zero vector (it gives a direction)");
      return false;
    }
    out = result;
    return true;
  }

  // Reads an optional rotation {"axis": [x, y, z], "angleDegrees": a}; keeps `out` when absent.
  bool readRotation(const Json& object, const std::string& path, std::string_view key, Quat& out) {
    const Json* value = member(object, key);
    if (!value) return true;
    const std::string here = child(path, key);
    if (!expectObject(*value, here, "{\"axis\": [x, y, z], \"angleDegrees\": a}")) return false;
    checkKeys(*value, here, {"axis", "angleDegrees"});
    Vec3 axis = Vec3::UnitY();
    Real degrees = 0;
    const std::size_t before = issueCount();
    if (!member(*value, "axis")) fail(child(here, "axis"), "is missing; give the rotation axis [x, y, z]");
    if (!member(*value, "angleDegrees")) fail(child(here, "angleDegrees"), "is missing; give the angle in degrees");
    readVec3(*value, here, "axis", axis, "", true);
    readReal(*value, here, "angleDegrees", degrees, Range::Any, "degrees");
    if (issueCount() != before) return false;
    const Real radians = degrees * kPi / 180;
    const Vec3 unitAxis = axis.normalized();
    if (!std::isfinite(radians) || !unitAxis.allFinite()) {
      fail(here, "the angle or axis is too large to turn into a rotation; give an angle in degrees "
                 "(e.g. 90) and an axis of ordinary length");
      return false;
    }
    out = Quat(Eigen::AngleAxis<Real>(radians, unitAxis));
    out.normalize();
    return true;
  }

  bool readEasing(const Json& object, const std::string& path, Easing& out) {
    if (!member(object, "easing")) return true;
    std::string name;
    if (!readString(object, path, "easing", name)) return false;
    const std::optional<Easing> easing = easingFromName(name);
    if (!easing) {
      fail(child(path, "easing"), "\"" + name + "\" is unknown; choose \"linear\" or \"smoothstep\"");
      return false;
    }
    out = *easing;
    return true;
  }

  // An array at object[key] (required or optional); null when absent or not an array.
  const Json* array(const Json& object, const std::string& path, std::string_view key,
                    bool required, std::string_view what) {
    const Json* value = member(object, key);
    if (!value) {
      if (required) fail(child(path, key), "is missing; give " + std::string(what));
      return nullptr;
    }
    if (!value->is_array()) {
      fail(child(path, key), "must be an array (" + std::string(what) + "), not " + typeName(*value));
      return nullptr;
    }
    return value;
  }

 private:
  const SceneLoadOptions& m_options;
  std::vector<SceneIssue>& m_issues;
};

std::string resolvePath(const std::string& file, const std::string& baseDirectory) {
  const std::filesystem::path path(file);
  if (path.is_absolute() || baseDirectory.empty()) return path.string();
  return (std::filesystem::path(baseDirectory) / path).lexically_normal().string();
}

// readReal for a material, spring or mass value, which must also stay within kMaxMaterialValue
// (World::createCloth refuses larger ones).
bool readMaterialValue(Reader& reader, const Json& object, const std::string& path,
                       std::string_view key, Real& out, Range range, std::string_view unit) {
  Real value = out;
  if (!reader.readReal(object, path, key, value, range, unit)) return false;
  if (value > kMaxMaterialValue) {
    reader.fail(child(path, key), "is " + formatNumber(value) + ", above " +
                                      formatNumber(kMaxMaterialValue) +
                                      " (kMaxMaterialValue, the largest value the solver's "
                                      "arithmetic carries); give a physical value");
    return false;
  }
  out = value;
  return true;
}

// A velocity within kMaxSpeed (World refuses faster ones); else an issue at `path`.
void checkSpeed(Reader& reader, const std::string& path, const Vec3& velocity, std::string_view what) {
  if (velocity.norm() <= kMaxSpeed) return;
  reader.fail(path, "is " + formatNumber(velocity.norm()) + " m/s, faster than " +
                        formatNumber(kMaxSpeed) + " m/s (kMaxSpeed), which the engine treats as "
                        "divergence; give " + std::string(what) + " a speed within it");
}

// A cloth of this size, model and world state together, fits in the available memory; else an
// issue at `path` naming `what` and the fix.
bool checkClothMemory(Reader& reader, const std::string& path, const std::string& what,
                      std::uint64_t vertices, std::uint64_t triangles, std::string_view fix) {
  const std::uint64_t bytes = ClothModel::estimatedBuildBytes(vertices, triangles) +
                              World::estimatedClothBytes(vertices, triangles);
  Status memory = checkMemory(bytes, "a cloth of " + std::to_string(vertices) + " vertices (" + what + ")", fix);
  if (memory.ok()) return true;
  reader.fail(path, memory.error().message);
  return false;
}

// Reads an OBJ file and checks its size against the limits; null on failure (issue recorded).
std::optional<TriangleMesh> readMesh(Reader& reader, const std::string& path,
                                     const std::string& file) {
  const std::string resolved = resolvePath(file, reader.options().baseDirectory);
  Result<TriangleMesh> mesh = ClothModel::readObj(resolved);
  if (!mesh.ok()) {
    reader.fail(path, mesh.error().message);
    return std::nullopt;
  }
  if (mesh->positions.size() > reader.options().maxVerticesPerCloth) {
    reader.fail(path, "OBJ file '" + resolved + "' has " + std::to_string(mesh->positions.size()) +
                          " vertices, more than the limit of " +
                          std::to_string(reader.options().maxVerticesPerCloth));
    return std::nullopt;
  }
  return std::move(mesh).value();
}

// ---------------------------------------------------------------------------------------------
// Cloths

void readMaterial(Reader& reader, const Json& object, const std::string& path, ClothMaterial& m) {
  if (!reader.expectObject(object, path, "a material: a preset name and/or fields")) return;
  reader.checkKeys(object, path,
                   {"preset", "arealDensity", "warpStretchStiffness", "weftStretchStiffness",
                    "shearStiffness", "bendingStiffness", "warpRestScale", "weftRestScale",
                    "stretchDamping", "shearDamping", "bendingDamping", "airDrag", "thickness",
                    "friction", "strainLimit"});
  std::string preset;
  if (reader.readString(object, path, "preset", preset) && Reader::member(object, "preset")) {
    Result<ClothMaterial> material = fabricPreset(preset);
    if (material.ok()) m = material.value();
    else reader.fail(child(path, "preset"), material.error().message);
  }
  readMaterialValue(reader, object, path, "arealDensity", m.arealDensity, Range::Positive, "kg/m²");
  readMaterialValue(reader, object, path, "warpStretchStiffness", m.warpStretchStiffness, Range::NonNegative, "N/m");
  readMaterialValue(reader, object, path, "weftStretchStiffness", m.weftStretchStiffness, Range::NonNegative, "N/m");
  readMaterialValue(reader, object, path, "shearStiffness", m.shearStiffness, Range::NonNegative, "N/m");
  readMaterialValue(reader, object, path, "bendingStiffness", m.bendingStiffness, Range::NonNegative, "N·m");
  readMaterialValue(reader, object, path, "warpRestScale", m.warpRestScale, Range::Positive, "factor");
  readMaterialValue(reader, object, path, "weftRestScale", m.weftRestScale, Range::Positive, "factor");
  readMaterialValue(reader, object, path, "stretchDamping", m.stretchDamping, Range::NonNegative, "N·s/m");
  readMaterialValue(reader, object, path, "shearDamping", m.shearDamping, Range::NonNegative, "N·s/m");
  readMaterialValue(reader, object, path, "bendingDamping", m.bendingDamping, Range::NonNegative, "N·m·s");
  readMaterialValue(reader, object, path, "airDrag", m.airDrag, Range::NonNegative, "N·s/m³");
  readMaterialValue(reader, object, path, "thickness", m.thickness, Range::Positive, "m");
  readMaterialValue(reader, object, path, "friction", m.friction, Range::NonNegative, "Coulomb coefficient");
  reader.readReal(object, path, "strainLimit", m.strainLimit, Range::NonNegative,
                  "strain l / l_rest - 1 (0 = off)");
}

void readSprings(Reader& reader, const Json& object, const std::string& path, MassSpringMaterial& m) {
  if (!reader.expectObject(object, path, "mass-spring stiffnesses and dampings")) return;
  reader.checkKeys(object, path,
                   {"structuralStiffness", "shearStiffness", "flexionStiffness",
                    "structuralDamping", "shearDamping", "flexionDamping"});
  readMaterialValue(reader, object, path, "structuralStiffness", m.structuralStiffness, Range::NonNegative, "N/m");
  readMaterialValue(reader, object, path, "shearStiffness", m.shearStiffness, Range::NonNegative, "N/m");
  readMaterialValue(reader, object, path, "flexionStiffness", m.flexionStiffness, Range::NonNegative, "N/m");
  readMaterialValue(reader, object, path, "structuralDamping", m.structuralDamping, Range::NonNegative, "N·s/m");
  readMaterialValue(reader, object, path, "shearDamping", m.shearDamping, Range::NonNegative, "N·s/m");
  readMaterialValue(reader, object, path, "flexionDamping", m.flexionDamping, Range::NonNegative, "N·s/m");
}

void readSolver(Reader& reader, const Json& object, const std::string& path, SolverSettings& s) {
  if (!reader.expectObject(object, path, "solver settings")) return;
  reader.checkKeys(object, path,
                   {"integrator", "substeps", "maxImplicitStep", "maxSubsteps", "maxPinTravelPerSubstep",
                    "strainRetrySubsteps",
                    "pinTeleportDistance", "pinTeleportAngle", "newtonIterations", "tightCgTolerance",
                    "tightSelfContactDensity", "tightPinTravel", "cgTolerance", "cgStopping",
                    "cgMaxIterations", "warmStart", "selfContactStiffness"});
  std::string name;
  if (reader.readString(object, path, "integrator", name) && Reader::member(object, "integrator")) {
    const std::optional<IntegratorKind> kind = integratorFromName(name);
    if (kind) {
      s.integrator = *kind;
    } else {
      std::string valid;
      for (IntegratorKind k : {IntegratorKind::ExplicitEuler, IntegratorKind::SymplecticEuler,
                               IntegratorKind::Midpoint, IntegratorKind::RungeKutta4,
                               IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2}) {
        valid += (valid.empty() ? "" : ", ") + std::string(integratorName(k));
      }
      reader.fail(child(path, "integrator"), "\"" + name + "\" is unknown; choose one of: " + valid);
    }
  }
  reader.readInteger(object, path, "substeps", s.substeps, 0, 100000);
  reader.readReal(object, path, "maxImplicitStep", s.maxImplicitStep, Range::Positive, "s");
  reader.readInteger(object, path, "maxSubsteps", s.maxSubsteps, 1, 1000000);
  reader.readInteger(object, path, "strainRetrySubsteps", s.strainRetrySubsteps, 0, 1000000);
  reader.readReal(object, path, "maxPinTravelPerSubstep", s.maxPinTravelPerSubstep, Range::NonNegative,
                  "mean edge lengths");
  reader.readReal(object, path, "pinTeleportDistance", s.pinTeleportDistance, Range::NonNegative,
                  "cloth sizes");
  reader.readReal(object, path, "pinTeleportAngle", s.pinTeleportAngle, Range::NonNegative, "rad");
  reader.readReal(object, path, "selfContactStiffness", s.selfContactStiffness, Range::NonNegative,
                  "multiples of the stretch stiffness, 0 = off");
  reader.readInteger(object, path, "newtonIterations", s.newtonIterations, 0, 100);
  reader.readReal(object, path, "tightCgTolerance", s.tightCgTolerance, Range::NonNegative,
                  "relative residual, 0 = off");
  reader.readReal(object, path, "tightSelfContactDensity", s.tightSelfContactDensity,
                  Range::Positive, "self-contacts per vertex");
  reader.readReal(object, path, "tightPinTravel", s.tightPinTravel, Range::Positive,
                  "mean edge lengths per substep");
  reader.readReal(object, path, "cgTolerance", s.cgTolerance, Range::Positive,
                  "relative, in the sense of cgStopping");
  std::string stopping;
  if (reader.readString(object, path, "cgStopping", stopping) && Reader::member(object, "cgStopping")) {
    if (stopping == "relativeResidual") {
      s.cgStopping = PcgStopping::RelativeResidual;
    } else if (stopping == "velocityError") {
      s.cgStopping = PcgStopping::VelocityError;
    } else {
      reader.fail(child(path, "cgStopping"),
                  "\"" + stopping + "\" is unknown; choose one of: relativeResidual, velocityError");
    }
  }
  reader.readInteger(object, path, "cgMaxIterations", s.cgMaxIterations, 1, 1000000);
  reader.readBool(object, path, "warmStart", s.warmStart);
}

std::optional<GridSettings> readGrid(Reader& reader, const Json& object, const std::string& path) {
  if (!reader.expectObject(object, path, "a rectangular grid")) return std::nullopt;
  reader.checkKeys(object, path, {"columns", "rows", "width", "height", "origin", "widthAxis", "heightAxis"});
  GridSettings grid;
  const std::size_t before = reader.issueCount();
  reader.readInteger(object, path, "columns", grid.columns, 2, 100000);
  reader.readInteger(object, path, "rows", grid.rows, 2, 100000);
  reader.readReal(object, path, "width", grid.width, Range::Positive, "m");
  reader.readReal(object, path, "height", grid.height, Range::Positive, "m");
  reader.readVec3(object, path, "origin", grid.origin, "m");
  reader.readVec3(object, path, "widthAxis", grid.widthAxis, "", true);
  reader.readVec3(object, path, "heightAxis", grid.heightAxis, "", true);
  if (reader.issueCount() != before) return std::nullopt;
  const std::uint64_t vertices = std::uint64_t(grid.columns) * grid.rows;
  if (vertices > reader.options().maxVerticesPerCloth) {
    reader.fail(path, std::to_string(grid.columns) + " x " + std::to_string(grid.rows) +
                          " vertices is more than the limit of " +
                          std::to_string(reader.options().maxVerticesPerCloth) +
                          " per cloth; use fewer columns and rows");
    return std::nullopt;
  }
  if (!checkClothMemory(reader, path, std::to_string(grid.columns) + " x " + std::to_string(grid.rows) + " grid",
                        vertices, 2 * std::uint64_t(grid.columns - 1) * (grid.rows - 1),
                        "use fewer columns and rows")) {
    return std::nullopt;
  }
  return grid;
}

// A pin selection: "vertices", "row" or "column". Appends to `vertices`.
bool readPinSelection(Reader& reader, const Json& pin, const std::string& path,
                      const ClothDescription& cloth, std::vector<Index>& vertices) {
  const int given = int(Reader::member(pin, "vertices") != nullptr) +
                    int(Reader::member(pin, "row") != nullptr) +
                    int(Reader::member(pin, "column") != nullptr);
  if (given != 1) {
    reader.fail(path, given == 0 ? "selects no vertices; give one of \"vertices\": [i, ...], "
                                   "\"row\": r or \"column\": c"
                                 : "give only one of \"vertices\", \"row\" and \"column\"");
    return false;
  }
  // A mesh's vertices are numbered as in its file (before welding); readCloth maps them.
  const MeshImport& import = cloth.model->meshImport();
  const Index vertexCount = import.modelVertexOfInput.empty() ? cloth.model->vertexCount()
                                                              : Index(import.modelVertexOfInput.size());
  if (const Json* list = Reader::member(pin, "vertices")) {
    const std::string here = child(path, "vertices");
    if (!list->is_array() || list->empty()) {
      reader.fail(here, "must be a non-empty array of vertex indices");
      return false;
    }
    bool ok = true;
    for (std::size_t k = 0; k < list->size(); ++k) {
      Index vertex = 0;
      if (reader.integerValue((*list)[k], child(here, k), vertex, 0, double(vertexCount) - 1)) {
        vertices.push_back(vertex);
      } else {
        ok = false;
      }
    }
    return ok;
  }
  const bool byRow = Reader::member(pin, "row") != nullptr;
  const std::string key = byRow ? "row" : "column";
  if (!cloth.grid) {
    reader.fail(child(path, key), "\"" + key + "\" selects pins on grid cloths only; this cloth is "
                                  "a mesh, so list its \"vertices\"");
    return false;
  }
  const Index columns = cloth.grid->columns, rows = cloth.grid->rows;
  Index line = 0;
  if (!reader.readInteger(pin, path, key, line, 0, double(byRow ? rows : columns) - 1)) return false;
  if (byRow) {
    for (Index c = 0; c < columns; ++c) vertices.push_back(line * columns + c);
  } else {
    for (Index r = 0; r < rows; ++r) vertices.push_back(r * columns + line);
  }
  return true;
}

std::optional<PinScript> readPinScript(Reader& reader, const Json& object, const std::string& path) {
  if (!reader.expectObject(object, path, "a pin script: anchor, easing, keyframes")) return std::nullopt;
  reader.checkKeys(object, path, {"anchor", "easing", "keyframes"});
  PinScript script;
  const std::size_t before = reader.issueCount();
  reader.readVec3(object, path, "anchor", script.anchor, "m");
  reader.readEasing(object, path, script.easing);
  const Json* keys = reader.array(object, path, "keyframes", true, "keyframes [{\"time\": s, ...}]");
  if (keys && keys->empty()) reader.fail(child(path, "keyframes"), "is empty; give at least one keyframe");
  if (keys) {
    PinKeyframe previous;
    for (std::size_t k = 0; k < keys->size() && !reader.full(); ++k) {
      const std::string here = child(child(path, "keyframes"), k);
      const Json& key = (*keys)[k];
      if (!reader.expectObject(key, here, "a keyframe: time, translation, rotation, scale")) continue;
      reader.checkKeys(key, here, {"time", "translation", "rotation", "scale"});
      PinKeyframe frame = previous;  // unspecified values hold
      reader.readKeyframeTime(key, here, k, previous.time, frame.time);
      reader.readVec3(key, here, "translation", frame.translation, "m");
      reader.readVec3(key, here, "scale", frame.scale, "");
      if (Reader::member(key, "rotation")) script.rotates = true;
      reader.readRotation(key, here, "rotation", frame.rotation);
      script.keyframes.push_back(frame);
      previous = frame;
    }
  }
  if (reader.issueCount() != before) return std::nullopt;
  return script;
}

// A pin group's "attachTo", kept until the colliders are read.
struct PendingAttachment {
  std::size_t cloth = 0;  // index into SceneDescription::cloths
  std::size_t group = 0;  // index into ClothDescription::pins
  std::string colliderName;
  std::string path;       // of the "attachTo" value
};

std::optional<ClothDescription> readCloth(Reader& reader, const Json& object,
                                          const std::string& path, std::size_t index,
                                          std::vector<PendingAttachment>& attachments) {
  if (!reader.expectObject(object, path, "a cloth")) return std::nullopt;
  reader.removedKey(object, path, "jointContactProjection",
                    "collider contacts, self-contacts and the strain limit are projected together "
                    "in every substep; delete the key");
  reader.checkKeys(object, path,
                   {"name", "grid", "mesh", "translation", "rotation", "forceModel", "material",
                    "springs", "solver", "selfCollision", "faceContacts", "initialPleats", "pins"});
  ClothDescription cloth;
  cloth.name = "cloth " + std::to_string(index);
  reader.readString(object, path, "name", cloth.name);

  // The model: a grid or an OBJ mesh.
  const Json* grid = Reader::member(object, "grid");
  const Json* mesh = Reader::member(object, "mesh");
  if ((grid != nullptr) == (mesh != nullptr)) {
    reader.fail(path, grid ? "give either \"grid\" or \"mesh\", not both"
                           : "has no shape; give \"grid\": {columns, rows, width, height, ...} or "
                             "\"mesh\": {\"obj\": \"file.obj\"}");
  } else if (grid) {
    const std::string here = child(path, "grid");
    cloth.grid = readGrid(reader, *grid, here);
    if (cloth.grid) {
      Result<ClothModel> model = ClothModel::grid(*cloth.grid);
      if (model.ok()) cloth.model = std::make_shared<const ClothModel>(std::move(model).value());
      else reader.fail(here, model.error().message);
    }
  } else if (reader.expectObject(*mesh, child(path, "mesh"), "{\"obj\": \"file.obj\", ...}")) {
    const std::string here = child(path, "mesh");
    reader.checkKeys(*mesh, here, {"obj", "warpDirection", "requireManifold", "weldVertices",
                                   "weldTolerance", "fixWinding"});
    MeshSettings settings;
    reader.readVec3(*mesh, here, "warpDirection", settings.warpDirection, "", true);
    reader.readBool(*mesh, here, "requireManifold", settings.requireManifold);
    reader.readBool(*mesh, here, "weldVertices", settings.weldVertices);
    if (reader.readReal(*mesh, here, "weldTolerance", settings.weldTolerance, Range::NonNegative,
                        "fraction of the mesh's bounding-box diagonal") &&
        !(settings.weldTolerance < 1)) {
      reader.fail(child(here, "weldTolerance"), "is " + formatNumber(settings.weldTolerance) +
                                                    "; give a fraction of the mesh's size below 1 "
                                                    "(default 1e-6)");
    }
    reader.readBool(*mesh, here, "fixWinding", settings.fixWinding);
    std::string file;
    if (!Reader::member(*mesh, "obj")) {
      reader.fail(child(here, "obj"), "is missing; give the path of a Wavefront OBJ file");
    } else if (reader.readString(*mesh, here, "obj", file)) {
      cloth.objPath = resolvePath(file, reader.options().baseDirectory);
      std::optional<TriangleMesh> triangles = readMesh(reader, child(here, "obj"), file);
      if (triangles && !checkClothMemory(reader, child(here, "obj"), "OBJ file '" + cloth.objPath + "'",
                                         triangles->positions.size(), triangles->indices.size() / 3,
                                         "simplify the mesh")) {
        triangles.reset();
      }
      if (triangles) {
        Result<ClothModel> model = ClothModel::fromMesh(*triangles, settings);
        if (model.ok()) cloth.model = std::make_shared<const ClothModel>(std::move(model).value());
        else reader.fail(child(here, "obj"), "OBJ file '" + cloth.objPath + "': " + model.error().message);
      }
    }
  }

  ClothSettings& settings = cloth.settings;
  reader.readVec3(object, path, "translation", settings.translation, "m");
  Quat rotation = Quat::Identity();
  if (Reader::member(object, "rotation") && reader.readRotation(object, path, "rotation", rotation)) {
    settings.rotation = rotation.toRotationMatrix();
  }
  std::string forceModel;
  if (reader.readString(object, path, "forceModel", forceModel) && Reader::member(object, "forceModel")) {
    if (forceModel == "baraff-witkin") settings.forceModel = ForceModel::BaraffWitkin;
    else if (forceModel == "mass-spring") settings.forceModel = ForceModel::MassSpring;
    else reader.fail(child(path, "forceModel"), "\"" + forceModel + "\" is unknown; choose \"baraff-witkin\" or \"mass-spring\"");
  }
  if (const Json* material = Reader::member(object, "material")) readMaterial(reader, *material, child(path, "material"), settings.material);
  if (const Json* springs = Reader::member(object, "springs")) readSprings(reader, *springs, child(path, "springs"), settings.springs);
  if (const Json* solver = Reader::member(object, "solver")) readSolver(reader, *solver, child(path, "solver"), settings.solver);
  reader.readBool(object, path, "selfCollision", settings.selfCollision);
  reader.readBool(object, path, "faceContacts", settings.faceContacts);

  if (const Json* pleats = Reader::member(object, "initialPleats")) {
    const std::string here = child(path, "initialPleats");
    if (reader.expectObject(*pleats, here, "{\"amplitude\": m, \"wavelength\": m}")) {
      reader.checkKeys(*pleats, here, {"amplitude", "wavelength"});
      reader.readReal(*pleats, here, "amplitude", cloth.pleats.amplitude, Range::Any, "m");
      reader.readReal(*pleats, here, "wavelength", cloth.pleats.wavelength, Range::Positive, "m");
      if (mesh && !grid) reader.fail(here, "pleats are defined on grid cloths only; remove them or use a \"grid\"");
    }
  }
  // Where the cloth starts (rotated, moved and pleated) must be within kMaxCoordinate, which
  // World::createCloth and setState demand.
  if (cloth.model && settings.translation.allFinite()) {
    Real farthest = 0;
    for (const Vec3& x : cloth.model->restPositions()) {
      farthest = std::max(farthest, (settings.rotation * x + settings.translation).cwiseAbs().maxCoeff());
    }
    farthest += std::abs(cloth.pleats.amplitude);
    if (!(farthest <= kMaxCoordinate)) {
      reader.fail(child(path, Reader::member(object, "translation") ? "translation" : "initialPleats"),
                  "places the cloth " + formatNumber(farthest) + " m from the origin, beyond the " +
                      formatNumber(kMaxCoordinate) +
                      " m a coordinate may have (kMaxCoordinate); keep the scene near the origin");
    }
  }

  // Pins need the model (indices are checked against it).
  if (const Json* pins = reader.array(object, path, "pins", false, "pin groups [{\"row\": r, \"script\": {...}}]")) {
    if (!cloth.model) {
      if (!pins->empty()) reader.fail(child(path, "pins"), "cannot be checked: the cloth's model could not be built (see the errors above)");
    } else {
      std::vector<std::string> pinnedAt(cloth.model->vertexCount());  // path of each pinned vertex
      for (std::size_t g = 0; g < pins->size() && !reader.full(); ++g) {
        const std::string here = child(child(path, "pins"), g);
        const Json& pin = (*pins)[g];
        if (!reader.expectObject(pin, here, "a pin group: vertices, row or column, and a script")) continue;
        reader.checkKeys(pin, here, {"vertices", "row", "column", "script", "attachTo"});
        PinGroup group;
        if (!readPinSelection(reader, pin, here, cloth, group.vertices)) continue;
        bool unique = true;
        const MeshImport& import = cloth.model->meshImport();
        for (Index& vertex : group.vertices) {
          const Index model = import.modelVertex(vertex);
          if (!pinnedAt[model].empty()) {
            reader.fail(here, "vertex " + std::to_string(vertex) + " is already pinned by " +
                                  pinnedAt[model] +
                                  (import.modelVertexOfInput.empty()
                                       ? ""
                                       : " (coincident vertices are welded into one)") +
                                  "; pin every vertex once");
            unique = false;
            break;
          }
          pinnedAt[model] = here;
          vertex = model;
        }
        if (!unique) continue;
        if (const Json* script = Reader::member(pin, "script")) {
          if (Reader::member(pin, "attachTo")) {
            reader.fail(child(here, "attachTo"), "a pin group either follows a script or rides on a collider; remove \"script\" or \"attachTo\"");
            continue;
          }
          group.script = readPinScript(reader, *script, child(here, "script"));
          if (!group.script) continue;
        }
        if (Reader::member(pin, "attachTo")) {
          // The collider is looked up by name once the colliders are read (resolveAttachments).
          std::string name;
          if (!reader.readString(pin, here, "attachTo", name)) continue;
          attachments.push_back({index, cloth.pins.size(), name, child(here, "attachTo")});
        }
        settings.pinnedVertices.insert(settings.pinnedVertices.end(), group.vertices.begin(), group.vertices.end());
        cloth.pins.push_back(std::move(group));
      }
    }
  }
  return cloth;
}

// ---------------------------------------------------------------------------------------------
// Colliders

std::optional<ColliderDescription> readCollider(Reader& reader, const Json& object,
                                                const std::string& path, std::size_t index) {
  if (!reader.expectObject(object, path, "a collider")) return std::nullopt;
  std::string type;
  if (!Reader::member(object, "type")) {
    reader.fail(child(path, "type"), "is missing; give \"plane\", \"sphere\", \"capsule\", \"box\" or \"mesh\"");
    return std::nullopt;
  }
  if (!reader.readString(object, path, "type", type)) return std::nullopt;
  const bool plane = type == "plane", sphere = type == "sphere", capsule = type == "capsule",
             box = type == "box", mesh = type == "mesh";
  if (!(plane || sphere || capsule || box || mesh)) {
    reader.fail(child(path, "type"), "\"" + type + "\" is unknown; choose \"plane\", \"sphere\", \"capsule\", \"box\" or \"mesh\"");
    return std::nullopt;
  }
  const std::size_t before = reader.issueCount();
  // Common keys plus the shape's own.
  if (plane) reader.checkKeys(object, path, {"type", "name", "position", "rotation", "linearVelocity", "angularVelocity", "friction", "motion", "normal"});
  if (sphere) reader.checkKeys(object, path, {"type", "name", "position", "rotation", "linearVelocity", "angularVelocity", "friction", "motion", "radius"});
  if (capsule) reader.checkKeys(object, path, {"type", "name", "position", "rotation", "linearVelocity", "angularVelocity", "friction", "motion", "radius", "halfLength"});
  if (box) reader.checkKeys(object, path, {"type", "name", "position", "rotation", "linearVelocity", "angularVelocity", "friction", "motion", "halfExtents"});
  if (mesh) reader.checkKeys(object, path, {"type", "name", "position", "rotation", "linearVelocity", "angularVelocity", "friction", "motion", "obj"});

  ColliderDescription collider;
  collider.name = type + " " + std::to_string(index);
  reader.readString(object, path, "name", collider.name);
  RigidMotion motion;
  reader.readVec3(object, path, "position", motion.pose.position, "m");
  reader.readRotation(object, path, "rotation", motion.pose.rotation);
  if (reader.readVec3(object, path, "linearVelocity", motion.linearVelocity, "m/s")) {
    checkSpeed(reader, child(path, "linearVelocity"), motion.linearVelocity, "a collider");
  }
  reader.readVec3(object, path, "angularVelocity", motion.angularVelocity, "rad/s");
  reader.readReal(object, path, "friction", collider.settings.friction, Range::NonNegative, "Coulomb coefficient");

  if (const Json* script = Reader::member(object, "motion")) {
    const std::string here = child(path, "motion");
    if (reader.expectObject(*script, here, "{\"easing\": ..., \"keyframes\": [...]}")) {
      reader.checkKeys(*script, here, {"easing", "keyframes"});
      if (Reader::member(object, "linearVelocity") || Reader::member(object, "angularVelocity")) {
        reader.fail(here, "keyframes set the velocities; remove \"linearVelocity\" and \"angularVelocity\" or the \"motion\"");
      }
      reader.readEasing(*script, here, collider.easing);
      const Json* keys = reader.array(*script, here, "keyframes", true, "keyframes [{\"time\": s, \"position\": [x, y, z]}]");
      if (keys && keys->empty()) reader.fail(child(here, "keyframes"), "is empty; give at least one keyframe");
      if (keys) {
        ColliderKeyframe previous{0, motion.pose.position, motion.pose.rotation};
        for (std::size_t k = 0; k < keys->size() && !reader.full(); ++k) {
          const std::string at = child(child(here, "keyframes"), k);
          const Json& key = (*keys)[k];
          if (!reader.expectObject(key, at, "a keyframe: time, position, rotation")) continue;
          reader.checkKeys(key, at, {"time", "position", "rotation"});
          ColliderKeyframe frame = previous;
          reader.readKeyframeTime(key, at, k, previous.time, frame.time);
          reader.readVec3(key, at, "position", frame.position, "m");
          if (Reader::member(key, "rotation")) collider.rotates = true;
          reader.readRotation(key, at, "rotation", frame.rotation);
          collider.keyframes.push_back(frame);
          previous = frame;
        }
      }
      // The start pose is the track's value at t = 0: the first keyframe's.
      if (!collider.keyframes.empty()) {
        motion.pose.position = collider.keyframes.front().position;
        motion.pose.rotation = collider.keyframes.front().rotation;
      }
    }
  }

  // The shape itself, at its start pose.
  std::optional<Shape> shape;
  auto take = [&](auto created, const std::string& at) {
    if (created.ok()) shape = std::move(created).value();
    else reader.fail(at, created.error().message);
  };
  auto required = [&](std::string_view key, std::string_view what) {
    if (Reader::member(object, key)) return true;
    reader.fail(child(path, key), "is missing; give " + std::string(what));
    return false;
  };
  if (plane) {
    Vec3 normal = Vec3::UnitY();
    if (required("normal", "the outward normal [x, y, z]") &&
        reader.readVec3(object, path, "normal", normal, "", true) && reader.issueCount() == before) {
      take(Plane::create(normal, motion), path);
    }
  } else if (sphere) {
    Real radius = 0;
    if (required("radius", "the radius in metres") &&
        reader.readReal(object, path, "radius", radius, Range::Positive, "m") && reader.issueCount() == before) {
      take(Sphere::create(radius, motion), path);
    }
  } else if (capsule) {
    Real radius = 0, halfLength = 0;
    const bool hasRadius = required("radius", "the radius in metres");
    const bool hasHalfLength = required("halfLength", "half the core segment's length in metres");
    const bool given = hasRadius && hasHalfLength;
    if (given && reader.readReal(object, path, "radius", radius, Range::Positive, "m") &&
        reader.readReal(object, path, "halfLength", halfLength, Range::NonNegative, "m") &&
        reader.issueCount() == before) {
      take(Capsule::create(radius, halfLength, motion), path);
    }
  } else if (box) {
    Vec3 halfExtents = Vec3::Ones();
    if (required("halfExtents", "the half edge lengths [x, y, z] in metres") &&
        reader.readVec3(object, path, "halfExtents", halfExtents, "m")) {
      if (!(halfExtents.array() > 0).all()) {
        reader.fail(child(path, "halfExtents"), "must be greater than 0 on every axis (m)");
      } else if (reader.issueCount() == before) {
        take(Box::create(halfExtents, motion), path);
      }
    }
  } else if (mesh) {
    std::string file;
    if (required("obj", "the path of a Wavefront OBJ file") && reader.readString(object, path, "obj", file)) {
      std::optional<TriangleMesh> triangles = readMesh(reader, child(path, "obj"), file);
      if (triangles && reader.issueCount() == before) {
        Result<TriangleMeshShape> created = TriangleMeshShape::create(triangles->positions, triangles->indices, motion);
        if (created.ok()) shape = std::move(created).value();
        else reader.fail(child(path, "obj"), "OBJ file '" + resolvePath(file, reader.options().baseDirectory) + "': " + created.error().message);
      }
    }
  }
  if (!shape || reader.issueCount() != before) return std::nullopt;
  collider.shape = std::move(*shape);
  return collider;
}

// ---------------------------------------------------------------------------------------------
// The document

void readCamera(Reader& reader, const Json& object, const std::string& path, SceneCamera& camera) {
  if (!reader.expectObject(object, path, "a camera: eye, target, up, verticalFovDegrees, resolution")) return;
  reader.checkKeys(object, path, {"eye", "target", "up", "verticalFovDegrees", "resolution"});
  reader.readVec3(object, path, "eye", camera.eye, "m");
  reader.readVec3(object, path, "target", camera.target, "m");
  reader.readVec3(object, path, "up", camera.up, "", true);
  Real fov = camera.verticalFovDegrees;
  if (reader.readReal(object, path, "verticalFovDegrees", fov, Range::Positive, "degrees")) {
    if (fov >= 180) reader.fail(child(path, "verticalFovDegrees"), "is " + formatNumber(fov) + "; give an angle below 180 degrees");
    else camera.verticalFovDegrees = fov;
  }
  if (const Json* resolution = Reader::member(object, "resolution")) {
    const std::string here = child(path, "resolution");
    if (!resolution->is_array() || resolution->size() != 2) {
      reader.fail(here, "must be [width, height] in pixels");
    } else {
      reader.integerValue((*resolution)[0], child(here, std::size_t(0)), camera.width, 16, 16384);
      reader.integerValue((*resolution)[1], child(here, std::size_t(1)), camera.height, 16, 16384);
    }
  }
  if ((camera.eye - camera.target).norm() == 0) reader.fail(child(path, "eye"), "is at the target; move the eye away from it");
}

// "windScript": {"easing": ..., "keyframes": [{"time": s, "wind": [x, y, z]}]}. A keyframe that
// leaves out "wind" holds the previous one's (the world's "wind" for the first); the start wind is
// the first keyframe's.
void readWindScript(Reader& reader, const Json& script, SceneDescription& scene) {
  const std::string here = "/world/windScript";
  if (!reader.expectObject(script, here, "{\"easing\": ..., \"keyframes\": [...]}")) return;
  reader.checkKeys(script, here, {"easing", "keyframes"});
  reader.readEasing(script, here, scene.windEasing);
  const Json* keys = reader.array(script, here, "keyframes", true, "keyframes [{\"time\": s, \"wind\": [x, y, z]}]");
  if (!keys) return;
  if (keys->empty()) reader.fail(child(here, "keyframes"), "is empty; give at least one keyframe");
  WindKeyframe previous{0, scene.wind};
  for (std::size_t k = 0; k < keys->size() && !reader.full(); ++k) {
    const std::string at = child(child(here, "keyframes"), k);
    const Json& key = (*keys)[k];
    if (!reader.expectObject(key, at, "a keyframe: time, wind")) continue;
    reader.checkKeys(key, at, {"time", "wind"});
    WindKeyframe frame = previous;
    reader.readKeyframeTime(key, at, k, previous.time, frame.time);
    if (reader.readVec3(key, at, "wind", frame.wind, "m/s")) {
      checkSpeed(reader, child(at, "wind"), frame.wind, "the wind");
    }
    scene.windKeyframes.push_back(frame);
    previous = frame;
  }
  if (!scene.windKeyframes.empty()) scene.wind = scene.windKeyframes.front().wind;
}

// Names each "attachTo" to its collider, once both are read.
void resolveAttachments(Reader& reader, const std::vector<PendingAttachment>& attachments,
                        SceneDescription& scene) {
  for (const PendingAttachment& attachment : attachments) {
    // A cloth that failed to parse is missing from the list (and the scene is refused anyway).
    if (attachment.cloth >= scene.cloths.size() ||
        attachment.group >= scene.cloths[attachment.cloth].pins.size()) {
      continue;
    }
    std::optional<std::size_t> found;
    std::string names;
    for (std::size_t k = 0; k < scene.colliders.size(); ++k) {
      if (scene.colliders[k].name == attachment.colliderName && !found) found = k;
      names += (names.empty() ? "\"" : ", \"") + scene.colliders[k].name + "\"";
    }
    if (!found) {
      reader.fail(attachment.path, "names no collider: \"" + attachment.colliderName + "\"; " +
                                       (names.empty() ? std::string("the scene has no colliders")
                                                      : "give one of " + names));
      continue;
    }
    scene.cloths[attachment.cloth].pins[attachment.group].attachedCollider = found;
  }
}

SceneDescription readScene(Reader& reader, const Json& document) {
  SceneDescription scene;
  std::vector<PendingAttachment> attachments;
  if (!document.is_object()) {
    reader.fail("", "a scene file must hold a JSON object, not " + typeName(document));
    return scene;
  }
  reader.checkKeys(document, "", {"version", "name", "description", "world", "run", "camera", "cloths", "colliders"});
  int version = 0;
  if (!Reader::member(document, "version")) {
    reader.fail("/version", "is missing; write \"version\": 1");
  } else if (reader.readInteger(document, "", "version", version, 1, 1000) && version != 1) {
    reader.fail("/version", "is " + std::to_string(version) + "; this program reads version 1");
  }
  reader.readString(document, "", "name", scene.name);
  reader.readString(document, "", "description", scene.description);
  if (const Json* world = Reader::member(document, "world")) {
    if (reader.expectObject(*world, "/world", "gravity and wind")) {
      reader.checkKeys(*world, "/world", {"gravity", "wind", "windScript"});
      if (reader.readVec3(*world, "/world", "gravity", scene.gravity, "m/s²") &&
          !(scene.gravity.norm() <= kMaxGravity)) {
        reader.fail("/world/gravity", "is " + formatNumber(scene.gravity.norm()) + " m/s² long, above " +
                                          formatNumber(kMaxGravity) +
                                          " m/s² (kMaxGravity: a second of fall would reach the "
                                          "speed the engine treats as divergence)");
      }
      if (reader.readVec3(*world, "/world", "wind", scene.wind, "m/s")) {
        checkSpeed(reader, "/world/wind", scene.wind, "the wind");
      }
      if (const Json* script = Reader::member(*world, "windScript")) readWindScript(reader, *script, scene);
    }
  }
  if (const Json* run = Reader::member(document, "run")) {
    if (reader.expectObject(*run, "/run", "frames and frame length")) {
      reader.checkKeys(*run, "/run", {"frames", "framesPerSecond", "frameDt"});
      reader.readInteger(*run, "/run", "frames", scene.frames, 1, 100'000'000);
      if (Reader::member(*run, "framesPerSecond") && Reader::member(*run, "frameDt")) {
        reader.fail("/run/frameDt", "give either \"framesPerSecond\" or \"frameDt\", not both");
      } else if (Reader::member(*run, "framesPerSecond")) {
        Real rate = 60;
        // 1 / rate, so that 60 gives exactly the 1.0 / 60.0 the curtain uses.
        if (reader.readReal(*run, "/run", "framesPerSecond", rate, Range::Positive, "Hz")) scene.frameDt = 1.0 / rate;
      } else {
        reader.readReal(*run, "/run", "frameDt", scene.frameDt, Range::Positive, "s");
      }
    }
  }
  if (const Json* camera = Reader::member(document, "camera")) readCamera(reader, *camera, "/camera", scene.camera);

  if (const Json* cloths = reader.array(document, "", "cloths", true, "the cloths [{\"grid\": {...}}]")) {
    if (cloths->empty()) reader.fail("/cloths", "is empty; a scene needs at least one cloth");
    for (std::size_t k = 0; k < cloths->size() && !reader.full(); ++k) {
      std::optional<ClothDescription> cloth = readCloth(reader, (*cloths)[k], child("/cloths", k), k, attachments);
      if (cloth) scene.cloths.push_back(std::move(*cloth));
    }
  }
  if (const Json* colliders = reader.array(document, "", "colliders", false, "the colliders [{\"type\": ...}]")) {
    for (std::size_t k = 0; k < colliders->size() && !reader.full(); ++k) {
      std::optional<ColliderDescription> collider = readCollider(reader, (*colliders)[k], child("/colliders", k), k);
      if (collider) scene.colliders.push_back(std::move(*collider));
    }
  }
  resolveAttachments(reader, attachments, scene);
  return scene;
}

// Builds the document through nlohmann's SAX interface, keeping the JSON Pointer of the value
// being read, so that a number no double holds ("1e400", which nlohmann refuses as it parses) is
// reported at its path, like every other bad value.
struct DocumentBuilder {
  explicit DocumentBuilder(Json& document) : dom(document, /*allow_exceptions=*/false) {}

  nlohmann::detail::json_sax_dom_parser<Json> dom;
  std::string errorPath;  // where parsing stopped ("" = the document)
  std::string message;    // why

  // One open object or array: the key of its current member, or the index of its current element.
  struct Level {
    bool array = false;
    std::string key;
    std::size_t index = 0;
  };
  std::vector<Level> levels;

  std::string path() const {
    std::string text;
    for (const Level& level : levels) {
      text = level.array ? child(text, level.index) : child(text, level.key);
    }
    return text;
  }
  // A value ended: the enclosing array moves to its next element.
  bool ended(bool ok) {
    if (!levels.empty() && levels.back().array) ++levels.back().index;
    return ok;
  }

  bool null() { return ended(dom.null()); }
  bool boolean(bool value) { return ended(dom.boolean(value)); }
  bool number_integer(Json::number_integer_t value) { return ended(dom.number_integer(value)); }
  bool number_unsigned(Json::number_unsigned_t value) { return ended(dom.number_unsigned(value)); }
  bool number_float(Json::number_float_t value, const Json::string_t& text) {
    return ended(dom.number_float(value, text));
  }
  bool string(Json::string_t& value) { return ended(dom.string(value)); }
  bool binary(Json::binary_t& value) { return ended(dom.binary(value)); }
  bool start_object(std::size_t size) {
    levels.push_back({false, {}, 0});
    return dom.start_object(size);
  }
  bool key(Json::string_t& name) {
    levels.back().key = name;
    return dom.key(name);
  }
  bool end_object() {
    levels.pop_back();
    return ended(dom.end_object());
  }
  bool start_array(std::size_t size) {
    levels.push_back({true, {}, 0});
    return dom.start_array(size);
  }
  bool end_array() {
    levels.pop_back();
    return ended(dom.end_array());
  }
  bool parse_error(std::size_t, const std::string& token, const nlohmann::detail::exception& error) {
    if (error.id == 406) {
      // Number overflow: a well-formed number beyond the doubles.
      errorPath = path();
      message = "is " + (token.size() > 40 ? token.substr(0, 40) + "..." : token) +
                ", beyond the largest double (about 1.8e308); give a finite number";
      return false;
    }
    // nlohmann's message names the line and column ("syntax error while parsing value - ...").
    std::string text = error.what();
    const std::size_t bracket = text.find("] ");
    if (bracket != std::string::npos) text = text.substr(bracket + 2);
    message = "malformed JSON: " + text;
    return false;
  }
};

}  // namespace

std::optional<IntegratorKind> integratorFromName(std::string_view name) {
  for (IntegratorKind kind : {IntegratorKind::ExplicitEuler, IntegratorKind::SymplecticEuler,
                              IntegratorKind::Midpoint, IntegratorKind::RungeKutta4,
                              IntegratorKind::ImplicitEuler, IntegratorKind::Bdf2}) {
    if (name == integratorName(kind)) return kind;
  }
  return std::nullopt;
}

std::optional<Easing> easingFromName(std::string_view name) {
  if (name == "linear") return Easing::Linear;
  if (name == "smoothstep") return Easing::Smoothstep;
  return std::nullopt;
}

SceneParseOutcome parseSceneText(std::string_view text, const SceneLoadOptions& options) {
  SceneParseOutcome outcome;
  Reader reader(options, outcome.issues);
  Json document;
  DocumentBuilder builder(document);
  bool parsed = false;
  try {
    parsed = Json::sax_parse(text.begin(), text.end(), &builder);
  } catch (const std::exception& error) {
    builder.message = std::string("malformed JSON: ") + error.what();
  }
  if (!parsed) {
    reader.fail(builder.errorPath, builder.message.empty() ? "malformed JSON" : builder.message);
    return outcome;
  }
  try {
    SceneDescription scene = readScene(reader, document);
    if (outcome.issues.empty()) outcome.scene = std::move(scene);
  } catch (const std::exception& error) {
    // Not expected (every access checks its type first); reported rather than thrown.
    reader.fail("", std::string("could not read the scene: ") + error.what());
  }
  return outcome;
}

SceneParseOutcome parseSceneFile(const std::string& path, SceneLoadOptions options) {
  Result<std::string> text = readInputFile(path, options.maxFileBytes, "scene file");
  if (!text.ok()) {
    SceneParseOutcome outcome;
    outcome.issues.push_back({"", text.error().message});
    return outcome;
  }
  options.baseDirectory = std::filesystem::path(path).parent_path().string();
  SceneParseOutcome outcome = parseSceneText(text.value(), options);
  if (outcome.scene && outcome.scene->name.empty()) {
    outcome.scene->name = std::filesystem::path(path).stem().string();
  }
  return outcome;
}

std::string formatIssues(const std::vector<SceneIssue>& issues) {
  std::string text;
  for (const SceneIssue& issue : issues) {
    if (!text.empty()) text += "\n";
    text += (issue.path.empty() ? std::string("/") : issue.path) + ": " + issue.message;
  }
  return text;
}

Result<SceneDescription> loadSceneFile(const std::string& path, SceneLoadOptions options) {
  SceneParseOutcome outcome = parseSceneFile(path, std::move(options));
  if (!outcome.scene) return Error{"scene file '" + path + "':\n" + formatIssues(outcome.issues)};
  return std::move(*outcome.scene);
}

Result<SceneDescription> loadSceneText(std::string_view json, const SceneLoadOptions& options) {
  SceneParseOutcome outcome = parseSceneText(json, options);
  if (!outcome.scene) return Error{formatIssues(outcome.issues)};
  return std::move(*outcome.scene);
}

}  // namespace weft
