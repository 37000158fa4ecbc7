#!/usr/bin/env python3
"""The benchmark report: pixelgym's benchmarks and the reference programs of ../shared/peers run
back to back on this machine, written to bench/RESULTS.md with the frames each program drew.

    make bench-report                 # installs what is missing, builds (Release, build/), runs this
    /usr/bin/python3 bench/report.py [--build build] [--repeats 5] [--out bench/RESULTS.md]
    /usr/bin/python3 bench/report.py --check-readme

Every measurement runs once per round, all of them one after the other, and the rounds repeat.
Each ratio's reference runs just before and just after its subject (its value is the mean of the
two), so that a change in the machine's speed reaches both sides alike. Each figure is the
median over the rounds; each ratio is the median of the ratios taken within one round. Before
each round the report waits (up to --idle-wait seconds) until other processes use less than a
tenth of a core, and it records how much CPU they took during the measurements.

What it measures, all with LP_NUM_THREADS=0 (pixelgym's default; llvmpipe draws on the calling
thread), one process unless said:
- render frames per second at 64 to 256 px (bench/render_bench) against the floor program
  (../shared/peers/floor: the least an OpenGL frame costs on this stack);
- pixel steps per second of every registered env at 84x84 (`pixelgym bench`) against MuJoCo 2.2.2
  + OSMesa stepping and drawing a dm_control-style cart-pole (../shared/peers/mujoco_osmesa), with
  dm_control's visuals and with all of them off;
- physics alone: each env without pixels, and the cart-pole against MuJoCo's physics step; the
  engine's physics steps per robot (bench/engine_bench);
- vector scaling: 8 envs on 2 threads against the same 8 on one, beside MuJoCo as two processes
  against one;
- the Python binding's vector env stepped from Python against the same from C++
  (bench/python_vector_bench.py);
- trainer throughput: `pixelgym train` on `make demo`'s settings (bench/train_throughput.sh)
  against the same vector env stepped without learning.
The report rewrites the block between the headline markers of README.md with the headline figures
written into RESULTS.md; --check-readme exits 1 when the two differ (a ctest test runs it).
"""

import argparse
import datetime
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PEERS = os.path.normpath(os.path.join(ROOT, "..", "shared", "peers"))
HEADLINE_BEGIN = "<!-- headline figures: written by bench/report.py from bench/RESULTS.md -->"
HEADLINE_END = "<!-- end of headline figures -->"
SIZES = (64, 84, 128, 256)
VECTOR_IDS = ("CartPoleSwingup-v0", "ArmReach-v0")
VECTOR_ENVS = 8
# make demo's env: CartPoleBalance-v1 from 64x64 anti-aliased grey frames, 3 stacked, action
# repeat 8 (the Makefile's DEMO_TRAIN; bench/train_throughput.sh trains on the same).
DEMO_ENV = ["CartPoleBalance-v1", "--set", "obs_mode=pixels", "--set", "width=64", "--set",
            "height=64", "--set", "msaa=4", "--set", "action_repeat=8", "--wrap", "grayscale",
            "--wrap", "frame_stack=3"]
DEMO_ACTION_REPEAT = 8


class BenchError(RuntimeError):
    pass


def run(argv, env=None, timeout=900):
    """Runs argv (LP_NUM_THREADS=0 unless env says otherwise) and returns its stdout."""
    full_env = dict(os.environ, LP_NUM_THREADS="0")
    full_env.update(env or {})
    result = subprocess.run(argv, cwd=ROOT, env=full_env, capture_output=True, text=True,
                            timeout=timeout)
    if result.returncode != 0:
        raise BenchError(f"{' '.join(argv)} exited {result.returncode}:\n{result.stderr[-2000:]}")
    return result.stdout


def field(text, name):
    """The last `name=NUMBER` in text, as a float."""
    found = re.findall(rf"\b{name}=([0-9.]+)", text)
    if not found:
        raise BenchError(f"expected {name}= in the output, got:\n{text[-1000:]}")
    return float(found[-1])


def busy_jiffies():
    with open("/proc/stat") as stat:
        values = [int(v) for v in stat.readline().split()[1:]]
    return sum(values[:3]) + sum(values[5:8])  # user nice system, irq softirq steal


def children_cpu_s():
    times = os.times()
    return times.children_user + times.children_system


def wait_until_idle(max_wait_s):
    """Waits until the machine's CPU use, ours excluded, is under 0.1 core over 2 s; returns the
    seconds waited."""
    hz = os.sysconf("SC_CLK_TCK")
    waited = 0.0
    while True:
        b0, c0 = busy_jiffies(), children_cpu_s() + time.process_time()
        time.sleep(2)
        b1, c1 = busy_jiffies(), children_cpu_s() + time.process_time()
        foreign = ((b1 - b0) / hz - (c1 - c0)) / 2
        if foreign < 0.1 or waited >= max_wait_s:
            return waited
        waited += 2


class Report:
    def __init__(self, args):
        self.args = args
        self.build = os.path.join(ROOT, args.build)
        self.pixelgym = os.path.join(self.build, "examples", "pixelgym")
        self.peers_bin = os.path.join(self.build, "peers")
        self.values = {}  # key -> list of per-round values
        self.renderer = ""

    # ---- programs ---------------------------------------------------------------------------
    def prepare(self):
        for program in (self.pixelgym, self.bench("render_bench"), self.bench("engine_bench"),
                        self.bench("frames_side_by_side")):
            if not os.access(program, os.X_OK):
                raise BenchError(f"{program} is missing: build first (make build, with "
                                 "PIXELGYM_BUILD_BENCH=ON), or run `make bench-report`")
        if not os.path.isdir(os.path.join(self.build, "python", "pixelgym")):
            raise BenchError(f"{self.build}/python/pixelgym is missing: the Python binding is built "
                             "with PIXELGYM_BUILD_PYTHON=ON (the default)")
        if not os.path.isfile(os.path.join(PEERS, "floor", "floor.c")):
            raise BenchError(f"the reference programs are missing: expected {PEERS}/floor/floor.c")
        status = subprocess.run(["dpkg-query", "-W", "-f=${Status}", "libmujoco-dev"],
                                capture_output=True, text=True)
        if "install ok installed" not in status.stdout:
            print("report: installing libmujoco-dev for the MuJoCo reference program", flush=True)
            sudo = [] if os.geteuid() == 0 else ["sudo"]
            subprocess.run(sudo + ["env", "DEBIAN_FRONTEND=noninteractive", "apt-get", "install",
                                   "-y", "-qq", "libmujoco-dev"], check=True,
                           stdout=subprocess.DEVNULL)
        os.makedirs(self.peers_bin, exist_ok=True)
        osmesa = subprocess.run(["pkg-config", "--cflags", "--libs", "osmesa"], check=True,
                                capture_output=True, text=True).stdout.split()
        run(["cc", "-O2", "-o", self.floor_bin, os.path.join(PEERS, "floor", "floor.c"),
             "-lOSMesa", "-lm"])
        run(["cc", "-O2", "-o", self.mujoco_bin, os.path.join(PEERS, "mujoco_osmesa", "bench.c"),
             "-lmujoco"] + osmesa + ["-lm"])
        self.ids = [line.split()[0] for line in run([self.pixelgym, "list"]).splitlines() if line]

    def bench(self, name):
        return os.path.join(self.build, "bench", name)

    @property
    def floor_bin(self):
        return os.path.join(self.peers_bin, "floor")

    @property
    def mujoco_bin(self):
        return os.path.join(self.peers_bin, "mujoco_bench")

    def mujoco(self, *flags):
        model = os.path.join(PEERS, "mujoco_osmesa", "cartpole.xml")
        return [self.mujoco_bin, model] + list(flags)

    # ---- the measurements: each returns {key: value} ----------------------------------------
    def probes(self):
        """Each ratio's two sides run seconds apart, the reference before and after its subject
        (the mean of the two is its value): this VM's speed moved by up to 2x over minutes with
        no other process running, and a pair measured a minute apart caught that instead."""
        probes = []
        for size in SIZES:
            probes.append((f"render {size}", lambda size=size: self.render_size(size)))
        mj_full = self.mujoco("-n", "300", "-w", "84", "-h", "84")
        mj_lite = self.mujoco("-n", "3000", "-w", "84", "-h", "84", "-lite")
        mj_phys = self.mujoco("-phys", "-n", "200000")
        cart = ["bench", "CartPoleSwingup-v0"]
        probes.append(("cart-pole against MuJoCo with dm_control's visuals", lambda: self.around(
            "mj:full", lambda: self.rate(mj_full),
            "env:CartPoleSwingup-v0:pixels", lambda: self.cli_rate(cart + ["--steps", "3000"]))))
        probes.append(("cart-pole without shadows against MuJoCo lite", lambda: self.around(
            "mj:lite", lambda: self.rate(mj_lite), "env:CartPoleSwingup-v0:noshadow",
            lambda: self.cli_rate(cart + ["--steps", "6000", "--set", "shadows=false"]))))
        probes.append(("cart-pole without pixels against MuJoCo's physics", lambda: self.around(
            "mj:phys", lambda: self.rate(mj_phys), "env:CartPoleSwingup-v0:state",
            lambda: self.cli_rate(cart + ["--steps", "20000", "--set", "obs_mode=state"]))))
        # Timed loops of a few tenths of a second or more: 5k-step loops of 40 ms moved by tens of
        # percent from round to round.
        for env_id in self.ids:
            if env_id == "CartPoleSwingup-v0":
                continue  # measured beside MuJoCo above
            grid = env_id == "GridWorld-v0"
            pixels = ["--set", "obs_mode=pixels"] if grid else []
            state = [] if grid else ["--set", "obs_mode=state"]
            pixel_steps, state_steps = ("30000", "500000") if grid else ("3000", "20000")
            probes.append((f"{env_id}", lambda i=env_id, p=pixels, s=state, n=pixel_steps,
                           m=state_steps: {
                f"env:{i}:pixels": self.cli_rate(["bench", i, "--steps", n] + p),
                f"env:{i}:state": self.cli_rate(["bench", i, "--steps", m] + s)}))
        for env_id in VECTOR_IDS:
            argv = ["bench", env_id, "--num-envs", str(VECTOR_ENVS), "--steps",
                    "8000" if env_id.startswith("CartPole") else "3000", "--threads"]
            probes.append((f"{env_id} vector", lambda i=env_id, argv=argv: self.around(
                f"vec:{i}:0", lambda: self.cli_rate(argv + ["0"]),
                f"vec:{i}:2", lambda: self.cli_rate(argv + ["2"]))))
        probes.append(("MuJoCo as 2 processes", lambda: self.around(
            "mj:full1", lambda: self.rate(mj_full), "mj:full2",
            lambda: self.two_processes(mj_full))))
        probes.append(("MuJoCo lite as 2 processes", lambda: self.around(
            "mj:lite1", lambda: self.rate(mj_lite), "mj:lite2",
            lambda: self.two_processes(mj_lite))))
        cpp_vector = ["bench", "CartPoleSwingup-v0", "--num-envs", str(VECTOR_ENVS), "--threads",
                      "2", "--steps", "8000"]
        probes.append(("Python vector env against C++", lambda: self.around(
            "py:cpp", lambda: self.cli_rate(cpp_vector), None, self.python_against_cpp)))
        demo_envs = ["bench"] + DEMO_ENV + ["--num-envs", "8", "--threads", "2", "--steps", "2000"]
        probes.append(("trainer against its envs alone", lambda: self.around(
            "train:envonly", lambda: self.cli_rate(demo_envs), "train", self.trainer)))
        probes.append(("engine_bench", self.engine))
        return probes

    def around(self, reference_key, reference, subject_key, subject):
        """The reference, the subject, the reference again: {reference_key: mean of the two,
        subject_key: the subject's value} (a subject returning a dict is merged as it is)."""
        before = reference()
        value = subject()
        after = reference()
        values = value if isinstance(value, dict) else {subject_key: value}
        return {reference_key: (before + after) / 2, **values}

    def render_size(self, size):
        frames = {64: 4000, 84: 4000, 128: 2500, 256: 800}[size]
        floor = [self.floor_bin, str(size), str(size), str(frames)]
        values = {}

        def scenes():
            for scene in ("cartpole", "arm"):
                for shadows in (False, True):
                    key = f"render:{size}:{scene}:{'on' if shadows else 'off'}"
                    argv = [self.bench("render_bench"), scene, str(size), str(size), str(frames)]
                    values[key] = self.render(argv + (["shadows"] if shadows else []))
            return values

        return self.around(f"render:{size}:floor", lambda: field(run(floor), "frames_per_s"),
                           None, scenes)

    def rate(self, argv):
        return field(run(argv), "steps_per_s")

    def render(self, argv):
        out = run(argv)
        self.renderer = re.search(r"renderer=(.*?) checksum", out).group(1)
        return field(out, "frames_per_s")

    def cli_rate(self, argv):
        return field(run([self.pixelgym] + argv), "steps_per_s")

    def two_processes(self, argv):
        env = dict(os.environ, LP_NUM_THREADS="0")
        procs = [subprocess.Popen(argv + ["-seed", str(seed)], cwd=ROOT, env=env, text=True,
                                  stdout=subprocess.PIPE, stderr=subprocess.DEVNULL)
                 for seed in (11, 22)]
        total = 0.0
        try:
            for proc in procs:
                out, _ = proc.communicate(timeout=900)
                if proc.returncode != 0:
                    raise BenchError(f"{' '.join(argv)} exited {proc.returncode}")
                total += field(out, "steps_per_s")
        finally:
            for proc in procs:
                if proc.poll() is None:
                    proc.kill()
                    proc.wait()
        return total

    def python_against_cpp(self):
        out = run(["/usr/bin/python3", os.path.join(ROOT, "bench", "python_vector_bench.py"),
                   "--rounds", "1", "--steps", "8000", "--num-envs", str(VECTOR_ENVS),
                   "--threads", "2", "--cli", self.pixelgym],
                  env={"PYTHONPATH": os.path.join(self.build, "python")})
        match = re.search(r"round 1: C\+\+ ([0-9,.]+)\s+Python vector ([0-9,.]+).*Python loop "
                          r"([0-9,.]+)", out)
        if not match:
            raise BenchError(f"python_vector_bench.py printed no round line:\n{out[-1000:]}")
        cpp, vector, loop = (float(v.replace(",", "")) for v in match.groups())
        # The script's own C++ figure runs only before its Python ones; the ratio's C++ side is
        # the same command run just before and just after the script (around()).
        return {"py:cpp_in_script": cpp, "py:vector": vector, "py:loop": loop}

    def trainer(self):
        out = run([os.path.join(ROOT, "bench", "train_throughput.sh"), self.args.build,
                   str(self.args.train_steps)])
        return {"train:fps": field(out, "env_steps_per_s"), "train:env_s": field(out, "env_s"),
                "train:act_s": field(out, "act_s"), "train:update_s": field(out, "update_s")}

    def engine(self):
        out = run([self.bench("engine_bench"), "--benchmark_format=json",
                   "--benchmark_min_time=0.2"])
        return {f"engine:{b['name']}": b["items_per_second"]
                for b in json.loads(out)["benchmarks"]}

    # ---- rounds -----------------------------------------------------------------------------
    def measure(self):
        probes = self.probes()
        hz = os.sysconf("SC_CLK_TCK")
        self.waited = 0.0
        measured_s = 0.0
        foreign_cpu_s = 0.0
        start = time.time()
        for round_index in range(self.args.repeats):
            self.waited += wait_until_idle(self.args.idle_wait)
            b0, c0, t0 = busy_jiffies(), children_cpu_s(), time.time()
            for name, probe in probes:
                for key, value in probe().items():
                    self.values.setdefault(key, []).append(value)
            b1, c1, t1 = busy_jiffies(), children_cpu_s(), time.time()
            measured_s += t1 - t0
            foreign_cpu_s += max(0.0, (b1 - b0) / hz - (c1 - c0))
            print(f"report: round {round_index + 1} of {self.args.repeats} took {t1 - t0:.0f} s",
                  flush=True)
            self.write_raw(round_index + 1)
        self.wall_s = time.time() - start
        self.foreign_cores = foreign_cpu_s / measured_s

    def write_raw(self, rounds):
        """Every round's values so far, in results/raw.json beside the report (written after each
        round, so a run that fails later keeps what it measured)."""
        folder = os.path.join(os.path.dirname(self.args.out_path), "results")
        os.makedirs(folder, exist_ok=True)
        raw = os.path.join(folder, "raw.json")
        with open(raw + ".tmp", "w") as f:
            json.dump({"rounds": rounds, "values": self.values}, f, indent=1)
        os.replace(raw + ".tmp", raw)

    def spread(self, key, base):
        """(lowest, highest) per-round ratio."""
        ratios = [a / b for a, b in zip(self.values[key], self.values[base])]
        return min(ratios), max(ratios)

    def median(self, key):
        return statistics.median(self.values[key])

    def ratio(self, key, base):
        """Median over the rounds of key / base, each round's pair measured in that round."""
        return statistics.median(a / b for a, b in zip(self.values[key], self.values[base]))

    # ---- frames -----------------------------------------------------------------------------
    def frames(self, out_dir):
        os.makedirs(out_dir, exist_ok=True)
        scratch = os.path.join(self.build, "bench-report-frames")
        shutil.rmtree(scratch, ignore_errors=True)
        os.makedirs(scratch)
        pictures = {}
        for size, scale in ((84, 3), (256, 1)):
            files = []
            floor = os.path.join(scratch, f"floor_{size}.ppm")
            run([self.floor_bin, str(size), str(size), "100", floor])
            files.append(floor)
            variants = [("full", []), ("lite", ["-lite"])] if size == 84 else [("full", [])]
            for name, flags in variants:
                path = os.path.join(scratch, f"mujoco_{name}_{size}.ppm")
                run(self.mujoco("-n", "60", "-w", str(size), "-h", str(size), "-ppm", path, *flags))
                files.append(path)
            envs = [("CartPoleBalance-v0", []), ("CartPoleBalance-v0", ["--set", "shadows=false"])]
            if size == 84:
                envs.append(("ArmReach-v0", []))
            for index, (env_id, sets) in enumerate(envs):
                path = os.path.join(scratch, f"pixelgym_{index}_{size}.png")
                run([self.pixelgym, "snapshot", env_id, "--observation", "--steps", "20", "--set",
                     f"width={size}", "--set", f"height={size}", "--out", path] + sets)
                files.append(path)
            picture = os.path.join(out_dir, f"frames_{size}.png")
            run([self.bench("frames_side_by_side"), picture, str(scale)] + files)
            pictures[size] = os.path.relpath(picture, os.path.dirname(self.args.out_path))
        return pictures

    # ---- facts ------------------------------------------------------------------------------
    def facts(self):
        def read(path, pattern):
            try:
                with open(path) as f:
                    match = re.search(pattern, f.read(), re.M)
                return match.group(1).strip() if match else "?"
            except OSError:
                return "?"

        def package(name):
            return subprocess.run(["dpkg-query", "-W", "-f=${Version}", name], capture_output=True,
                                  text=True).stdout or "not installed"

        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                                capture_output=True, text=True).stdout.strip() or "?"
        changed = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--",
                                  ".", ":!bench/RESULTS.md", ":!bench/results", ":!README.md"],
                                 cwd=ROOT, capture_output=True, text=True).stdout.strip()
        memory_kib = int(read("/proc/meminfo", r"^MemTotal:\s+(\d+)").replace("?", "0"))
        compiler = read(os.path.join(self.build, "CMakeCache.txt"),
                        r"^CMAKE_CXX_COMPILER:\w+=(.*)$")
        compiler_version = subprocess.run([compiler, "--version"], capture_output=True,
                                          text=True).stdout.splitlines()[0] if compiler != "?" else "?"
        cpu_model = read("/proc/cpuinfo", r"^model name\s*:(.*)$")
        cart_physics = self.values["engine:BM_CartPole"]
        build_type = read(os.path.join(self.build, "CMakeCache.txt"),
                          r"^CMAKE_BUILD_TYPE:\w+=(.*)$")
        return [
            ("date (UTC)", datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M")),
            ("commit", commit + (" with uncommitted changes" if changed else "")),
            ("CPU", f"{cpu_model}, {os.cpu_count()} cores"),
            ("memory", f"{memory_kib / 1024 / 1024:.1f} GiB"),
            ("system", f"Debian {read('/etc/debian_version', r'(.*)')}, Linux {platform.release()}"),
            ("renderer", f"{self.renderer} (Mesa {package('libosmesa6')}, OSMesa)"),
            ("compiler", f"{compiler_version}, {build_type}"),
            ("Bullet", package("libbullet-dev")),
            ("LibTorch", f"{package('libtorch-dev')}, OpenBLAS {package('libopenblas0-pthread')}"),
            ("MuJoCo (reference)", package("libmujoco-dev")),
            ("Python", f"{platform.python_version()}, NumPy {package('python3-numpy')}"),
            ("rounds", f"{self.args.repeats} (figures are medians over them), {self.wall_s / 60:.1f} "
                       f"minutes in all"),
            ("other processes", f"{self.foreign_cores:.2f} cores on average during the measurements "
                                f"(waited {self.waited:.0f} s for them before rounds)"),
            ("the machine's own speed", f"`engine_bench`'s cart-pole, the same code every round, "
                                        f"ran at {min(cart_physics):,.0f} to {max(cart_physics):,.0f} "
                                        f"physics steps per second over the rounds: absolute "
                                        f"figures move with that; the ratios pair runs made seconds "
                                        f"apart"),
            ("LP_NUM_THREADS", "0 for every program (pixelgym's default: llvmpipe draws on the "
                               "calling thread)"),
        ]

    # ---- writing ----------------------------------------------------------------------------
    def headline(self):
        v, r = self.median, self.ratio
        return "\n".join([
            f"- **{v('env:CartPoleSwingup-v0:pixels'):,.0f} pixel steps per second on one core**: "
            f"`CartPoleSwingup-v0` steps Bullet and draws 84x84 RGB with shadows at "
            f"**{r('env:CartPoleSwingup-v0:pixels', 'mj:full'):.0f}x** the rate of MuJoCo + OSMesa "
            f"drawing a cart-pole with dm_control's visuals ({v('mj:full'):,.0f} per second), and "
            f"without shadows at **{r('env:CartPoleSwingup-v0:noshadow', 'mj:lite'):.1f}x** MuJoCo "
            f"with every visual off. The 7-joint mesh arm of `ArmReach-v0`: "
            f"{v('env:ArmReach-v0:pixels'):,.0f} per second.",
            f"- **{r('render:84:cartpole:off', 'render:84:floor'):.1f}x the floor**: pixelgym's "
            f"cart-pole frame at 84x84 (sky, checker floor, specular light) draws at "
            f"{v('render:84:cartpole:off'):,.0f} frames per second, a bare OpenGL program drawing a "
            f"flat cart-pole on the same OSMesa at {v('render:84:floor'):,.0f}.",
            f"- **{r('vec:CartPoleSwingup-v0:2', 'vec:CartPoleSwingup-v0:0'):.2f}x on 2 threads**: "
            f"8 envs in `AsyncVectorEnv` against the same 8 on one thread "
            f"(`ArmReach-v0`: {r('vec:ArmReach-v0:2', 'vec:ArmReach-v0:0'):.2f}x; MuJoCo as two "
            f"processes against one: {r('mj:full2', 'mj:full1'):.2f}x).",
            f"- **{r('py:vector', 'py:cpp'):.2f}x C++ from Python**: the binding's vector env "
            f"stepped from a Python loop, against the same from C++.",
            f"- **{v('train:fps'):,.0f} env steps per second of PPO from pixels, updates "
            f"included** ({v('train:fps') * DEMO_ACTION_REPEAT:,.0f} control steps with action "
            f"repeat 8), on `make demo`'s settings: "
            f"{r('train:fps', 'train:envonly'):.2f}x "
            f"the {v('train:envonly'):,.0f} env steps per second of its 8 envs stepped alone.",
        ])

    def write(self):
        out_path = self.args.out_path
        pictures = self.frames(os.path.join(os.path.dirname(out_path), "results"))
        v, r = self.median, self.ratio
        lines = [
            "# Benchmark results",
            "",
            "Written by `make bench-report` (bench/report.py; bench/README.md says what it runs). "
            "Each figure is the median over the rounds; each ratio is the median of the ratios "
            "taken within one round, where the reference ran just before and just after "
            "pixelgym (the mean of the two). Every round's value is in "
            "[results/raw.json](results/raw.json).",
            "",
            "## Machine",
            "",
            "| | |",
            "|---|---|",
        ]
        lines += [f"| {name} | {value} |" for name, value in self.facts()]
        lines += ["", "## Headline figures", "", HEADLINE_BEGIN, self.headline(), HEADLINE_END, ""]
        lines += [
            "How far the headline ratios moved from round to round (each round's ratio pairs runs "
            "made seconds apart):",
            "",
            "| ratio | median | lowest round | highest round |",
            "|---|---:|---:|---:|",
        ]
        for name, key, base in (
                ("`CartPoleSwingup-v0` pixels / MuJoCo, dm_control's visuals",
                 "env:CartPoleSwingup-v0:pixels", "mj:full"),
                ("`CartPoleSwingup-v0` without shadows / MuJoCo lite",
                 "env:CartPoleSwingup-v0:noshadow", "mj:lite"),
                ("cart-pole frame / floor, 84x84", "render:84:cartpole:off", "render:84:floor"),
                ("`CartPoleSwingup-v0`, 2 threads / 1", "vec:CartPoleSwingup-v0:2",
                 "vec:CartPoleSwingup-v0:0"),
                ("`ArmReach-v0`, 2 threads / 1", "vec:ArmReach-v0:2", "vec:ArmReach-v0:0"),
                ("MuJoCo, 2 processes / 1", "mj:full2", "mj:full1"),
                ("Python vector env / C++", "py:vector", "py:cpp"),
                ("PPO training / its envs alone", "train:fps", "train:envonly")):
            low, high = self.spread(key, base)
            lines.append(f"| {name} | {r(key, base):.2f}x | {low:.2f}x | {high:.2f}x |")
        lines.append("")

        lines += [
            "## Render frames per second",
            "",
            "`bench/render_bench SCENE SIZE SIZE FRAMES [shadows]` (move the robot, update the "
            "scene, draw, read back RGB) against `../shared/peers/floor` (a minimal OpenGL 3.3 "
            "program: ~150 triangles, one diffuse light, flat background, no physics). Ratios "
            "to the floor in parentheses.",
            "",
            "| size | floor | cart-pole | cart-pole, shadows | arm | arm, shadows |",
            "|---|---:|---:|---:|---:|---:|",
        ]
        for size in SIZES:
            cells = [f"{v(f'render:{size}:floor'):,.0f}"]
            for scene in ("cartpole", "arm"):
                for shadows in ("off", "on"):
                    key = f"render:{size}:{scene}:{shadows}"
                    cells.append(f"{v(key):,.0f} ({r(key, f'render:{size}:floor'):.2f}x)")
            lines.append(f"| {size}x{size} | " + " | ".join(cells) + " |")

        lines += [
            "",
            "## Pixel steps per second, every env",
            "",
            "`pixelgym bench ID` (one env, this thread, seeded random actions, resets included: "
            "physics + render + observation) at each env's defaults (84x84 RGB with shadows; "
            "GridWorld with `obs_mode=pixels`), and `--set obs_mode=state` for the same without "
            "pixels. The reference: `../shared/peers/mujoco_osmesa` stepping its cart-pole and "
            f"drawing it at 84x84, with dm_control's visuals (shadow map, reflective floor, "
            f"skybox, 4x MSAA): **{v('mj:full'):,.0f}** steps per second; with all of them off "
            f"(`-lite`): **{v('mj:lite'):,.0f}**. The last column divides each env's pixel rate by "
            "that MuJoCo rate, measured just before and after `CartPoleSwingup-v0` in the same "
            "round: a scale for every env, paired and like for like only for that cart-pole.",
            "",
            "| env | pixels | no pixels | pixels / MuJoCo with dm_control's visuals |",
            "|---|---:|---:|---:|",
        ]
        for env_id in self.ids:
            lines.append(f"| `{env_id}` | {v(f'env:{env_id}:pixels'):,.0f} | "
                         f"{v(f'env:{env_id}:state'):,.0f} | "
                         f"{r(f'env:{env_id}:pixels', 'mj:full'):.1f}x |")
        lines += [
            "",
            f"Without shadows `CartPoleSwingup-v0` steps at "
            f"{v('env:CartPoleSwingup-v0:noshadow'):,.0f} per second: "
            f"**{r('env:CartPoleSwingup-v0:noshadow', 'mj:lite'):.2f}x** MuJoCo with every visual "
            "off.",
            "",
            "## Physics alone",
            "",
            f"The cart-pole without pixels (`pixelgym bench CartPoleSwingup-v0 --set "
            f"obs_mode=state`: a 0.01 s control step of two 5 ms Bullet steps, the env's reward "
            f"and its observation) "
            f"steps at {v('env:CartPoleSwingup-v0:state'):,.0f} per second against "
            f"{v('mj:phys'):,.0f} for MuJoCo's `mj_step` on its cart-pole (RK4, 0.01 s, nothing "
            f"else): **{r('env:CartPoleSwingup-v0:state', 'mj:phys'):.2f}x**. The engine alone "
            "(`bench/engine_bench`: `World::step` under changing torques, physics steps of the "
            "default 1/240 s per second):",
            "",
            "| robot | physics steps per second |",
            "|---|---:|",
        ]
        for key in sorted(k for k in self.values if k.startswith("engine:")):
            lines.append(f"| {key.split(':', 1)[1].removeprefix('BM_')} | {v(key):,.0f} |")

        lines += [
            "",
            "## Vector scaling",
            "",
            f"`pixelgym bench ID --num-envs {VECTOR_ENVS} --threads T`: T=0 is `SyncVectorEnv` (one "
            "thread), T=2 `AsyncVectorEnv` on 2 threads; total env steps per second. The "
            "reference scales by processes, as dm_control users do: two MuJoCo processes at once "
            "against one.",
            "",
            "| program | one thread | 2 threads (or processes) | scaling |",
            "|---|---:|---:|---:|",
        ]
        for env_id in VECTOR_IDS:
            lines.append(f"| `{env_id}`, {VECTOR_ENVS} envs | {v(f'vec:{env_id}:0'):,.0f} | "
                         f"{v(f'vec:{env_id}:2'):,.0f} | "
                         f"{r(f'vec:{env_id}:2', f'vec:{env_id}:0'):.2f}x |")
        for key, name in (("full", "dm_control's visuals"), ("lite", "visuals off")):
            lines.append(f"| MuJoCo + OSMesa, {name} | {v(f'mj:{key}1'):,.0f} | "
                         f"{v(f'mj:{key}2'):,.0f} | {r(f'mj:{key}2', f'mj:{key}1'):.2f}x |")

        lines += [
            "",
            "## Python against C++",
            "",
            f"`bench/python_vector_bench.py --num-envs {VECTOR_ENVS} --threads 2 --steps 8000`, one "
            "of its rounds per round here (`CartPoleSwingup-v0` at 84x84, total env steps per "
            f"second), with `pixelgym bench CartPoleSwingup-v0 --num-envs {VECTOR_ENVS} --threads 2 "
            "--steps 8000` run just before and just after it as the C++ side (the script's own "
            "C++ figure, measured only before its Python ones, is `py:cpp_in_script` in "
            "raw.json). Ratios are medians of the rounds' ratios, so they need not equal the "
            "ratio of the medians beside them.",
            "",
            "| stepped by | env steps per second | ratio to C++ |",
            "|---|---:|---:|",
            f"| C++ (`pixelgym bench --num-envs {VECTOR_ENVS} --threads 2`) | {v('py:cpp'):,.0f} | 1.00x |",
            f"| Python: `pixelgym.make_vec(..., num_threads=2)` | {v('py:vector'):,.0f} | "
            f"{r('py:vector', 'py:cpp'):.2f}x |",
            f"| Python: a loop over {VECTOR_ENVS} `pixelgym.make` envs | {v('py:loop'):,.0f} | "
            f"{r('py:loop', 'py:cpp'):.2f}x |",
            "",
            "## Trainer throughput",
            "",
            f"`bench/train_throughput.sh {self.args.build} {self.args.train_steps}`: `pixelgym "
            "train` with `make demo`'s settings (PPO, `CartPoleBalance-v1` from 64x64 grey frames, "
            "3 stacked, action repeat 8, 8 envs on 2 threads, 128 steps per update), medians over "
            "the updates after the first. Against it, the same 8 envs stepped by "
            "`pixelgym bench` without learning.",
            "",
            "| | |",
            "|---|---:|",
            f"| env steps per second, updates included | {v('train:fps'):,.0f} |",
            f"| control steps per second (x{DEMO_ACTION_REPEAT}, action repeat) | "
            f"{v('train:fps') * DEMO_ACTION_REPEAT:,.0f} |",
            f"| the same envs without learning | {v('train:envonly'):,.0f} |",
            f"| training / without learning | {r('train:fps', 'train:envonly'):.2f}x |",
            f"| seconds per update: stepping the envs | {v('train:env_s'):.3f} |",
            f"| seconds per update: the policy acting | {v('train:act_s'):.3f} |",
            f"| seconds per update: the epochs | {v('train:update_s'):.3f} |",
            "",
            "## Frames each program drew",
            "",
            "84x84, enlarged 3 times (each pixel a 3x3 block). Left to right: the floor program; "
            "MuJoCo + OSMesa with dm_control's visuals; MuJoCo with all of them off; pixelgym's "
            "cart-pole (`CartPoleBalance-v0`, the scene `CartPoleSwingup-v0` draws, 20 random "
            "steps in) with shadows and without; `ArmReach-v0`. Each is the observation the "
            "program measured above produces.",
            "",
            f"![frames at 84x84]({pictures[84]})",
            "",
            "256x256, actual size: the floor program, MuJoCo with dm_control's visuals, pixelgym's "
            "cart-pole with shadows and without.",
            "",
            f"![frames at 256x256]({pictures[256]})",
            "",
        ]
        with open(out_path + ".tmp", "w") as f:
            f.write("\n".join(lines))
        os.replace(out_path + ".tmp", out_path)
        print(f"report: wrote {os.path.relpath(out_path, ROOT)}")
        if not self.args.readme:
            return
        if os.path.abspath(out_path) != os.path.join(ROOT, "bench", "RESULTS.md"):
            print("report: README.md left as it is (its headline figures are bench/RESULTS.md's)")
        elif update_readme(self.headline()):
            print("report: README.md's headline figures now match")


def readme_path():
    return os.path.join(ROOT, "README.md")


def headline_block(text, where):
    begin, end = text.find(HEADLINE_BEGIN), text.find(HEADLINE_END)
    if begin < 0 or end < begin:
        raise BenchError(f"{where}: expected the markers {HEADLINE_BEGIN!r} and {HEADLINE_END!r}")
    return begin, end + len(HEADLINE_END)


def update_readme(headline):
    with open(readme_path()) as f:
        text = f.read()
    begin, end = headline_block(text, "README.md")
    updated = text[:begin] + HEADLINE_BEGIN + "\n" + headline + "\n" + HEADLINE_END + text[end:]
    if updated == text:
        return False
    with open(readme_path() + ".tmp", "w") as f:
        f.write(updated)
    os.replace(readme_path() + ".tmp", readme_path())
    return True


def check_readme(results):
    """0 when README.md's headline block is RESULTS.md's, else 1 with both printed."""
    blocks = []
    for path in (readme_path(), results):
        with open(path) as f:
            text = f.read()
        begin, end = headline_block(text, os.path.relpath(path, ROOT))
        blocks.append(text[begin:end])
    if blocks[0] == blocks[1]:
        print(f"README.md's headline figures match {os.path.relpath(results, ROOT)}")
        return 0
    print(f"README.md's headline figures differ from {os.path.relpath(results, ROOT)}'s (run "
          f"`make bench-report`, which writes both, or copy the block):\n--- README.md\n"
          f"{blocks[0]}\n--- {os.path.relpath(results, ROOT)}\n{blocks[1]}")
    return 1


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter,
                                     epilog=__doc__.split("\n", 1)[1])
    parser.add_argument("--build", default="build", help="build folder (Release; default build)")
    parser.add_argument("--repeats", type=int, default=5, help="rounds (default 5)")
    parser.add_argument("--out", default="bench/RESULTS.md", help="the report (default "
                        "bench/RESULTS.md; its pictures go to results/ beside it)")
    parser.add_argument("--train-steps", type=int, default=16384,
                        help="env steps of each trainer run (default 16384: 16 updates)")
    parser.add_argument("--idle-wait", type=float, default=300,
                        help="most seconds to wait before a round for other processes to go "
                        "idle (default 300)")
    parser.add_argument("--no-readme", dest="readme", action="store_false",
                        help="leave README.md's headline block as it is")
    parser.add_argument("--check-readme", action="store_true",
                        help="only compare README.md's headline block with the report's")
    args = parser.parse_args()
    args.out_path = os.path.join(ROOT, args.out)
    try:
        if args.check_readme:
            return check_readme(args.out_path)
        if args.repeats < 1:
            raise BenchError(f"--repeats: expected at least 1, got {args.repeats}")
        report = Report(args)
        report.prepare()
        report.measure()
        report.write()
    except (BenchError, subprocess.CalledProcessError, subprocess.TimeoutExpired) as error:
        print(f"report: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
