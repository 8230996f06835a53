// Settings of ClothRenderer: camera, resolution, colours, light; and the per-frame timing it reports.
// Every field has a default that shows the curtain (docs/curtain-benchmark.md) from the front.
#pragma once

#include <weft/Math.h>

namespace weft {

/// A linear RGB colour, each channel 0–1 (written to 8-bit output without gamma).
struct ColorRgb {
  float r = 0;  ///< red, 0–1
  float g = 0;  ///< green, 0–1
  float b = 0;  ///< blue, 0–1
  /// Same channels.
  friend bool operator==(const ColorRgb&, const ColorRgb&) = default;
};

/// A pinhole camera looking from eye at target.
struct CameraSettings {
  Vec3 eye{0.0, 1.25, 3.2};      ///< m, camera position (world)
  Vec3 target{0.0, 1.25, 0.0};   ///< m, the point seen at the centre of the image
  Vec3 up{0.0, 1.0, 0.0};        ///< world direction that appears up; need not be unit or orthogonal
  double verticalFovDegrees = 45.0;  ///< degrees, full vertical field of view; raising it zooms out
  double nearDistance = 0.05;    ///< m, near clipping distance; raising it improves depth precision
  double farDistance = 100.0;    ///< m, far clipping distance
};

/// Everything ClothRenderer draws with, apart from the scene itself.
struct RenderSettings {
  CameraSettings camera;          ///< where the picture is taken from
  int width = 1280;               ///< pixels; the context's framebuffer is resized to match
  int height = 720;               ///< pixels
  ColorRgb background{0.86f, 0.88f, 0.91f};   ///< clear colour
  ColorRgb clothFront{0.22f, 0.42f, 0.78f};   ///< cloth colour on the side its triangles wind counter-clockwise
  ColorRgb clothBack{0.86f, 0.56f, 0.26f};    ///< cloth colour on the other side
  ColorRgb wireframeColor{0.08f, 0.09f, 0.12f};  ///< colour of the wireframe overlay
  bool wireframe = false;         ///< draws triangle edges over the shaded cloth
  bool drawColliders = true;      ///< draws the collider primitives of the scene
  /// Direction towards the light; in camera space (x right, y up, z towards the viewer) when
  /// lightFollowsCamera, else in world space. Need not be unit length.
  Vec3 lightDirection{0.35, 0.6, 1.0};
  bool lightFollowsCamera = true;  ///< keeps the visible side lit wherever the camera goes
  float ambient = 0.25f;           ///< 0–1, share of the colour seen in shadow; raising it flattens shading
};

/// Measured cost of one frame (std::chrono::steady_clock, wall time on the calling thread).
struct FrameTiming {
  double renderMs = 0;    ///< ms, float conversion + upload + draw + glFinish (the rasteriser's work is inside)
  double readbackMs = 0;  ///< ms, glReadPixels + row flip; 0 when the frame was not read back
};

}  // namespace weft
