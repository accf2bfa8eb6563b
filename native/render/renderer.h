// The image loop: tiles of the camera's pixel window rendered by a TBB pool, each finished tile
// handed to the caller while the others go on, progress readable, cancel honoured within a few
// milliseconds. Output: linear RGBA float, rows from the top.
#pragma once

#include "camera/camera.h"
#include "core/cancel_poll.h"
#include "render/aovs.h"
#include "render/integrator.h"
#include "render/render_settings.h"

#include <atomic>
#include <functional>
#include <stdexcept>
#include <vector>

namespace toyrt {

// A rectangle of the window, in window pixels (rows from the top).
struct Tile {
  int x = 0, y = 0, width = 0, height = 0;
};

struct RenderResult {
  int width = 0, height = 0;  // of the camera's pixel window
  std::vector<float> rgba;    // width * height * 4, rows from the top
  AovBuffers passes;          // the passes asked for (render's `passes`), the same layout
  bool cancelled = false;
  size_t tiles_done = 0, tiles_total = 0;
  double render_ms = 0.0;
  double cancel_latency_ms = 0.0;  // from the cancel request to every worker stopped (when cancelled)
  // Samples: those every pixel was given (fewer when the time limit stopped the render), their
  // mean over the pixels (below samples_done where adaptive sampling stopped pixels early), and
  // the progress so far, in samples over the whole image (what "Sample k/N" shows).
  int samples_done = 0;
  double mean_samples = 0.0;
  double progress_samples = 0.0;
  bool time_limit_reached = false;
  LightSampling light_sampling = LightSampling::All;  // the estimator used ("auto" resolved)
};

// A render refused before allocating: its image would not fit in memory (Python: MemoryError).
struct RenderTooLarge : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes a render of `camera`'s pixel window will allocate: its framebuffer and passes, a copy of
// them for the caller (the binding returns one), the tile list and a per-thread allowance.
size_t render_memory_estimate(const Camera& camera, const RenderSettings& settings, const AovRequest& passes = {});
// Memory the system can give now (Linux MemAvailable; the physical memory elsewhere), in bytes.
size_t available_memory_bytes();

// Called on the calling thread (never on a worker) for each finished tile, with the image so far:
// the tile's pixels are final (with a time limit: final for the passes done so far, the tile is
// handed over again after each pass). `should_cancel` is polled on the calling thread every few
// milliseconds; when it returns true, workers stop within a few samples (the flag is read every
// kCancelCheckSamples samples inside a pixel, so even 100,000 samples per pixel stop at once)
// and render() returns with cancelled set; the pixels they were on are left unfinished. Either callback may be empty.
constexpr int kCancelCheckSamples = 8;

using TileSink = std::function<void(const Tile&, const RenderResult&)>;

// Renders the committed scene in place (no copy of it: the caller keeps it unchanged until this
// returns). Throws std::invalid_argument for settings out of bounds or a material id without its
// material, std::logic_error for an uncommitted scene, RenderTooLarge before allocating.
// `passes`: the render passes to fill beside Combined (aovs.h); none costs nothing.
RenderResult render(const Scene& scene, const Camera& camera, const RenderSettings& settings,
                    const TileSink& on_tile = {}, const CancelPoll& should_cancel = {}, const AovRequest& passes = {});

}  // namespace toyrt
