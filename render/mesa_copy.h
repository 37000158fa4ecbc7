// Copies of Mesa in one process: threads that draw with contexts of different copies rasterize
// in parallel.
#pragma once

#include <cstddef>
#include <string>

namespace pixelgym::render {

/// llvmpipe, Mesa's software rasterizer, has one screen per loaded library, and it rasterizes the
/// frames of every context of that screen under one lock: threads drawing at once with contexts
/// of one libOSMesa take turns. A library loaded a second time in a link namespace of its own
/// (dlmopen) is a separate copy, with its own screen and lock, and threads drawing with contexts
/// of different copies run in parallel (figures: docs/design-notes.md, "Rendering").
///
/// Copy 0 is libOSMesa.so.8 loaded into the process (dlopen, when the first OSMesa context is
/// made; not linked, so a machine without it still runs EGL). Copies 1, 2, ... are private
/// copies of the same file, loaded when a context first asks for them and kept until the process
/// ends. The copies run
/// the same code on the same machine, so a scene drawn with any copy gives the same bytes.
///
/// A context is created in the copy its creator names (Context's `mesa_copy`, ContextGroup's; copy
/// 0 by default). make_vec gives the envs of worker thread w copy w (see vector::make_vec).
///
/// Limits: glibc has 16 link namespaces per process, and copies loaded later share a small
/// reserve of static thread-local storage, which in a plain process ran out at the 10th copy. So
/// pixelgym loads at most `max_copies() - 1` private copies (7 by default; the environment
/// variable PIXELGYM_MESA_COPIES=N sets the total N, and 1 disables private copies); copy
/// numbers wrap around at that. A copy that fails to load is copy 0 instead: the same frames,
/// drawn in turn with copy 0's other contexts; the first such fallback prints one line to stderr
/// with the reason.
class MesaCopy {
 public:
  /// The most copies, copy 0 included: PIXELGYM_MESA_COPIES when set (1 to 16), else 8. Throws
  /// std::invalid_argument when the variable is set to anything else.
  static int max_copies();
  /// The copy a context asking for `copy` gets: `copy` modulo max_copies(), loaded if need be,
  /// or 0 when it could not be loaded (then `why_not` of that copy says why). Throws
  /// std::invalid_argument for copy < 0, and as max_copies(). Thread-safe.
  static int resolve(int copy);
  /// Whether copy `copy` is loaded (copy 0: once any context was made).
  static bool loaded(int copy);
  /// Why `copy` could not be loaded, or "" when it was (or was never asked for).
  static std::string why_not(int copy);
  /// Bytes the private copies' mallocs have handed out and not had back (the sum of glibc's
  /// mallinfo2 uordblks + hblkhd of each loaded copy's own libc, which the process's mallinfo2
  /// does not count); 0 when none is loaded. For leak tests. Thread-safe.
  static std::size_t private_malloc_in_use();
};

}  // namespace pixelgym::render
