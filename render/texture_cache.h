// Private to render/: the renderer's textures (loaded once per path) and which one texture unit 0
// holds.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>

#include "pixelgym/render/gl.h"
#include "pixelgym/render/gl_object.h"
#include "pixelgym/render/scene.h"

namespace pixelgym::render {

/// Albedo textures by file path, plus a white texel for untextured draws (so that the sampler
/// always has a complete texture). Binds on texture unit 0 and remembers what it bound there, to
/// skip redundant binds.
class TextureCache {
 public:
  /// Creates the white texel (a context must be current).
  TextureCache();

  /// Binds the texture of the PNG at `path` (loaded, mipmapped and kept on first use) on unit 0.
  /// Throws std::runtime_error naming the file when it cannot be read.
  void bind(const std::string& path);
  /// Binds the texture of `image` (uploaded, mipmapped and kept on first use, with mirrored
  /// repeat) on texture unit `unit`, leaving unit 0 active. Uploads of images that are gone
  /// everywhere else are deleted once more than a few are kept.
  void bind_image(const std::shared_ptr<const TextureImage>& image, int unit);
  /// Binds the white texel on unit 0.
  void bind_white();
  /// Forgets what unit 0 holds: call after anything else bound a texture there.
  void forget_binding() { bound_ = 0; }

 private:
  void bind_name(GLuint name);

  GlTexture white_;
  struct Uploaded {
    std::weak_ptr<const TextureImage> image;
    GlTexture texture;
  };

  std::map<std::string, GlTexture> by_path_;
  std::map<std::uint64_t, Uploaded> by_serial_;
  GLuint bound_ = 0;  // on texture unit 0
};

}  // namespace pixelgym::render
