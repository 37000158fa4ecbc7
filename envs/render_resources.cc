#include "pixelgym/envs/render_resources.h"

namespace pixelgym {

RenderResources::~RenderResources() = default;

}  // namespace pixelgym
