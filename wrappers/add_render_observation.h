// AddRenderObservation: puts the env's render() frame into the observation
// (gymnasium.wrappers.AddRenderObservation, formerly PixelObservationWrapper).
#pragma once

#include <memory>
#include <string>

#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// After every reset and step, renders a frame (env.render(), "rgb_array") and adds it to the
/// observation, as a uint8 Box [0, 255] of the frame's shape (H, W, 3):
/// - render_only: the observation is the frame alone;
/// - a Dict observation: the frame is added under `render_key`, first, before the inner keys
///   (Gymnasium's order);
/// - any other observation: Dict{obs_key: the inner observation, render_key: the frame}.
///
/// The frame's shape comes from `metadata().render_shape` (pixel tasks and GridWorld declare it
/// from their render_width / render_height), so the space is exact before any episode; Gymnasium
/// instead resets the env and renders once in its constructor, which this wrapper never does.
///
/// Differences from Gymnasium 1.x: `render_only` defaults to false here (Gymnasium: true), as
/// pixelgym's tasks already observe pixels and the usual wish is to add the render-sized frame
/// beside them. Per step, env.render() returns a new frame (one allocation, the renderer's),
/// which is copied into the caller's buffer.
class AddRenderObservation final : public ObservationWrapper {
 public:
  /// Throws std::invalid_argument when the inner env's metadata lacks "rgb_array" in
  /// render_modes or a render_shape of (H, W, 3) with H, W >= 1, when a key is empty, when
  /// `render_key` is already a key of a Dict observation (listing its keys), and when
  /// `render_key` == `obs_key` for a non-Dict observation.
  explicit AddRenderObservation(std::unique_ptr<Env> env, bool render_only = false,
                                const std::string& render_key = "pixels",
                                const std::string& obs_key = "state");

  /// Whether the observation is the frame alone.
  bool render_only() const { return render_only_; }
  /// The frame's key in a Dict observation.
  const std::string& render_key() const { return render_key_; }
  /// The inner observation's key when a non-Dict observation is wrapped in a Dict.
  const std::string& obs_key() const { return obs_key_; }

 protected:
  std::string type_name() const override { return "AddRenderObservation"; }
  void observation(const Value& in, Value& out) override;

 private:
  enum class Layout { kRenderOnly, kDict, kWrapped };
  bool render_only_;
  std::string render_key_;
  std::string obs_key_;
  Layout layout_;
  Shape frame_shape_;
};

}  // namespace pixelgym::wrappers
