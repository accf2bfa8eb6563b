// The image loop: tiles of the camera's pixel window rendered by a TBB pool, each finished tile
// handed to the caller while the others go on, progress readable, cancel honoured within a few
// milliseconds. Output: linear RGBA float, rows from the top.
#pragma once

#include "camera/camera.h"
#include "render/integrator.h"

#include <atomic>
#include <functional>
#include <vector>

namespace toyrt {

struct RenderSettings {
  int samples = 16;        // per pixel, on a Sobol-Owen pattern, box filter of one pixel
  int tile_size = 32;      // pixels
  int threads = 0;         // 0: all cores
  IntegratorSettings integrator;
};

// A rectangle of the window, in window pixels (rows from the top).
struct Tile {
  int x = 0, y = 0, width = 0, height = 0;
};

struct RenderResult {
  int width = 0, height = 0;  // of the camera's pixel window
  std::vector<float> rgba;    // width * height * 4, rows from the top
  bool cancelled = false;
  size_t tiles_done = 0, tiles_total = 0;
  double render_ms = 0.0;
  double cancel_latency_ms = 0.0;  // from the cancel request to every worker stopped (when cancelled)
};

// Called on the calling thread (never on a worker) for each finished tile, with the image so far:
// the tile's pixels are final. `should_cancel` is polled on the calling thread every few
// milliseconds; when it returns true, workers stop at their next pixel row and render() returns
// with cancelled set. Either callback may be empty.
using TileSink = std::function<void(const Tile&, const RenderResult&)>;
using CancelPoll = std::function<bool()>;

RenderResult render(const RenderScene& scene, const Camera& camera, const RenderSettings& settings,
                    const TileSink& on_tile = {}, const CancelPoll& should_cancel = {});

}  // namespace toyrt
