"""A few thousand steps of every registered env leave memory flat: Python objects (tracemalloc)
and the C heap (glibc's mallinfo2: the bytes malloc has handed out and not had back, which holds
pixelgym's C++ buffers). Not the resident set size: in a process that has freed memory before,
a leak fills freed pages first and the resident size does not move."""

import ctypes
import gc
import os
import tracemalloc

import pytest

import numpy as np
from conftest import ENV_IDS

import pixelgym

# Under AddressSanitizer (make test-asan) malloc and the resident size are ASan's, not glibc's.
pytestmark = pytest.mark.skipif(os.environ.get("PIXELGYM_UNDER_ASAN") == "1",
                                reason="memory is measured in the Release build, not under ASan")


class _MallInfo2(ctypes.Structure):
    _fields_ = [(name, ctypes.c_size_t) for name in (
        "arena", "ordblks", "smblks", "hblks", "hblkhd", "usmblks", "fsmblks", "uordblks",
        "fordblks", "keepcost")]


_mallinfo2 = ctypes.CDLL("libc.so.6").mallinfo2
_mallinfo2.restype = _MallInfo2


def malloc_in_use_kib():
    """Bytes in use from malloc, every arena (threads' too) and mmap'd chunks, in KiB."""
    info = _mallinfo2()
    return (info.uordblks + info.hblkhd) // 1024


def run_steps(env, steps, rng):
    env.reset(seed=int(rng.integers(1000)))
    for _ in range(steps):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()


def growth(run, warmup, measured):
    """Python heap growth (bytes, tracemalloc) and C heap growth (KiB) over `measured` steps after
    `warmup` steps."""
    run(warmup)
    gc.collect()
    tracemalloc.start()
    python_before = tracemalloc.get_traced_memory()[0]
    heap_before = malloc_in_use_kib()
    run(measured)
    gc.collect()
    python_after = tracemalloc.get_traced_memory()[0]
    tracemalloc.stop()
    return python_after - python_before, malloc_in_use_kib() - heap_before


def test_single_envs_do_not_leak(env_id):
    # 3,000 steps; a leaked 84x84x3 observation per step would be about 52 MiB of C heap over the
    # 2,500 measured, a leaked Python object of 100 bytes per step 250 KB.
    env = pixelgym.make(env_id, max_episode_steps=200)
    env.action_space.seed(0)
    rng = np.random.default_rng(0)
    # An env whose look varies per episode (the -distracting ids) fills bounded caches in its first
    # episodes: the renderer keeps up to 16 backgrounds per image size and a texture per image
    # shown (16 procedural ones). 64 resets fill them before anything is measured.
    for seed in range(64):
        env.reset(seed=seed)
    python_bytes, heap = growth(lambda steps: run_steps(env, steps, rng), 500, 2500)
    assert python_bytes < 64 * 1024, f"{env_id}: Python heap grew {python_bytes} bytes"
    assert heap < 1024, f"{env_id}: the C heap grew {heap} KiB"
    env.close()


def test_vector_envs_do_not_leak():
    for mode in ("NextStep", "SameStep"):
        envs = pixelgym.make_vec("CartPoleSwingup-v0", 4, num_threads=2, autoreset_mode=mode,
                                 max_episode_steps=50, wrap=["record_episode_statistics"])
        envs.reset(seed=0)
        rng = np.random.default_rng(1)

        def run(steps):
            for _ in range(steps):
                envs.step(rng.uniform(-1, 1, (4, 1)).astype(np.float32))

        python_bytes, heap = growth(run, 300, 1500)
        assert python_bytes < 64 * 1024, f"{mode}: Python heap grew {python_bytes} bytes"
        assert heap < 1024, f"{mode}: the C heap grew {heap} KiB"
        envs.close()


def test_the_measure_sees_a_leak():
    env = pixelgym.make("CartPoleSwingup-v0")
    kept = []

    def leaky(steps):
        env.reset(seed=0)
        for _ in range(steps):
            kept.append(env.step(np.zeros(1, np.float32))[0])  # a leak of every observation

    python_bytes, heap = growth(leaky, 10, 500)
    # 500 observations of 21 KiB of pixels each: about 10 MiB of C heap.
    assert python_bytes >= 64 * 1024 and heap >= 1024, (python_bytes, heap)


def resident_mib():
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * 4096 / (1 << 20)


def test_vector_envs_made_and_closed_leave_memory_flat():
    # The resident size here, not the C heap: the leak this guards against was in the libc of a
    # private Mesa copy (render/mesa_copy.h), which the process's mallinfo2 does not see. Each
    # make_vec with 2 worker threads and close() left a malloc arena behind, 6-13 MiB resident
    # per cycle; now the 8 cycles after warm-up grow by about 4 MiB in all.
    def cycle():
        envs = pixelgym.make_vec("CartPoleSwingup-v0", 4, num_threads=2)
        envs.reset(seed=0)
        envs.step(np.zeros((4, 1), np.float32))
        envs.close()

    for _ in range(3):
        cycle()
    gc.collect()
    before = resident_mib()
    for _ in range(8):
        cycle()
    gc.collect()
    grown = resident_mib() - before
    assert grown < 16, f"8 make_vec/close cycles grew the resident size by {grown:.1f} MiB"
