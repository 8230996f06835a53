// HeadlessCapture: render a simulation without a window, GPU or display server, and save it as
// PNG frames and an MP4 video. A square of cotton drops onto a sphere; every frame is drawn with
// weft::ClothRenderer into an EGL context (Mesa's llvmpipe on a machine without a GPU), read back,
// queued to an ImageSequenceWriter (PNG encoding runs on its own thread) and piped to ffmpeg.
// Without ffmpeg the video is skipped with a notice and the PNG frames are still written.
//
//   weft-example-headless-capture [output directory = capture] [frames = 60] [WIDTHxHEIGHT = 640x360]
//   ffmpeg is optional: apt-get install ffmpeg
#include <weft/Weft.h>
#include <weft/render/ClothRenderer.h>
#include <weft/render/EglContext.h>
#include <weft/render/ImageSequenceWriter.h>
#include <weft/render/VideoWriter.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

constexpr double kFrameDt = 1.0 / 60.0;  // s
constexpr double kSphereRadius = 0.3;    // m

template <typename T>
bool failed(const weft::Result<T>& result) {
  if (result) return false;
  std::fprintf(stderr, "headless-capture: %s\n", result.error().message.c_str());
  return true;
}

bool failed(const weft::Status& status) {
  if (status) return false;
  std::fprintf(stderr, "headless-capture: %s\n", status.error().message.c_str());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string directory = argc > 1 ? argv[1] : "capture";
  const int frames = argc > 2 ? std::atoi(argv[2]) : 60;
  int width = 640, height = 360;
  if (argc > 3 && std::sscanf(argv[3], "%dx%d", &width, &height) != 2) width = 0;
  if (frames <= 0 || width < 16 || height < 16 || width % 2 || height % 2) {
    std::fprintf(stderr, "usage: %s [directory] [frames > 0] [WIDTHxHEIGHT, even, >= 16]\n", argv[0]);
    return 2;
  }

  // The simulation: a 1 m square, level, 0.4 m above a sphere.
  weft::GridSettings grid;
  grid.columns = 21;
  grid.rows = 21;
  grid.width = 1.0;
  grid.height = 1.0;
  grid.origin = weft::Vec3(-0.5, 0.7, 0.5);
  grid.heightAxis = weft::Vec3(0.0, 0.0, -1.0);  // front faces up
  auto model = weft::ClothModel::grid(grid);
  if (failed(model)) return 1;
  weft::World world;
  weft::ClothSettings settings;
  settings.material = weft::cottonFabric();
  auto cloth = world.createCloth(std::make_shared<const weft::ClothModel>(std::move(model).value()),
                                 settings);
  if (failed(cloth)) return 1;
  auto sphere = weft::Sphere::create(kSphereRadius);
  if (failed(sphere) || failed(world.addCollider(sphere.value()))) return 1;

  // The renderer: a headless context, a camera, and what the colliders look like.
  weft::ContextSettings contextSettings;
  contextSettings.width = width;
  contextSettings.height = height;
  auto context = weft::EglContext::create(contextSettings);
  if (failed(context)) return 1;
  weft::RenderSettings renderSettings;
  renderSettings.width = width;
  renderSettings.height = height;
  renderSettings.camera.eye = weft::Vec3(1.4, 1.1, 1.7);
  renderSettings.camera.target = weft::Vec3(0.0, 0.1, 0.0);
  auto renderer = weft::ClothRenderer::create(context.value(), renderSettings);
  if (failed(renderer)) return 1;
  const std::vector<weft::ColliderPrimitive> colliders{
      weft::SpherePrimitive{weft::Vec3(0.0, 0.0, 0.0), kSphereRadius * 0.98}};

  // The outputs: numbered PNG files, and a video when ffmpeg is installed.
  auto pictures = weft::ImageSequenceWriter::open(directory);
  if (failed(pictures)) return 1;
  weft::VideoSettings videoSettings;
  videoSettings.width = width;
  videoSettings.height = height;
  videoSettings.fps = 1.0 / kFrameDt;
  const std::string videoPath = directory + "/capture.mp4";
  auto video = weft::VideoWriter::open(videoPath, videoSettings);
  if (failed(video)) return 1;
  if (!video->enabled()) std::printf("headless-capture: %s\n", video->notice().c_str());
  std::printf("headless-capture: %d frames at %d x %d on %s\n", frames, width, height,
              context->renderer().c_str());

  weft::Image image;
  double renderMs = 0;
  for (int frame = 0; frame < frames; ++frame) {
    const weft::StepStatus status = world.step(kFrameDt);
    if (weft::hasFlag(status, weft::StepStatus::RolledBack)) {
      std::fprintf(stderr, "headless-capture: frame %d: %s\n", frame + 1, weft::describe(status).c_str());
      return 1;
    }
    auto view = world.renderView(cloth.value());
    if (failed(view)) return 1;
    const weft::ClothRenderView views[] = {view.value()};
    auto timing = renderer->renderFrame(weft::RenderScene{views, colliders}, image);
    if (failed(timing)) return 1;
    renderMs += timing->renderMs + timing->readbackMs;
    if (failed(pictures->write(image)) || failed(video->write(image))) return 1;
  }
  if (failed(pictures->finish()) || failed(video->finish())) return 1;

  std::printf("headless-capture: ok, %d PNG frames in %s (%s ... %s), %s, %.2f ms per frame to draw "
              "and read back\n",
              pictures->framesQueued(), directory.c_str(), pictures->framePath(0).c_str(),
              pictures->framePath(frames - 1).c_str(),
              video->enabled() ? ("video " + videoPath).c_str() : "no video (ffmpeg not found)",
              renderMs / frames);
  return 0;
}
