"""Running the mcrt executable: `mcrt render ... --stats` (render_seconds is the
rendering alone) and `mcrt diff ... --json`."""
import hashlib
import json
import shlex
import subprocess
from pathlib import Path

# Flags the bench sets itself; a configuration may not pass them.
RESERVED = {"-o", "--output", "--spp", "--seed", "--width", "--height", "--threads",
            "--stats", "--quiet", "--max-depth"}


def parse_flags(text):
    flags = shlex.split(text)
    for f in flags:
        if f.split("=", 1)[0] in RESERVED:
            raise SystemExit(f"mcrt flags {text!r}: {f.split('=', 1)[0]} is set by the bench "
                             "(use the bench's --spp/--seeds/--size/--threads/--max-depth)")
    return flags


class Mcrt:
    def __init__(self, binary, threads, log):
        self.binary = str(Path(binary).resolve())
        if not Path(self.binary).is_file():
            raise SystemExit(f"mcrt binary {binary} not found (build it with scripts/build.sh)")
        self.sha256 = hashlib.sha256(Path(self.binary).read_bytes()).hexdigest()
        self.threads = threads
        self.log = log  # called with (purpose, command line) of every run

    def _run(self, cmd, purpose):
        self.log(purpose, shlex.join(cmd))
        p = subprocess.run(cmd, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError(f"{shlex.join(cmd)} failed ({p.returncode}): {p.stderr.strip()}")
        return p

    def render(self, scene, out, spp, seed, width, height, flags=(), max_depth=None, purpose="render"):
        """Renders to `out` (.exr); returns the --stats JSON (render_seconds, ...)."""
        out = Path(out)
        stats = out.with_suffix(".stats.json")
        cmd = [self.binary, "render", str(scene), "-o", str(out), "--spp", str(spp),
               "--seed", str(seed), "--width", str(width), "--height", str(height),
               "--threads", str(self.threads), "--stats", str(stats), "--quiet", *flags]
        if max_depth is not None:
            cmd += ["--max-depth", str(max_depth)]
        self._run(cmd, purpose)
        s = json.loads(stats.read_text())
        stats.unlink()
        s["command"] = shlex.join(cmd)
        return s

    def diff(self, image, reference, purpose="diff"):
        """`mcrt diff IMAGE REFERENCE --json`: rmse, mse, relmse, mean_diff_percent."""
        return json.loads(self._run([self.binary, "diff", str(image), str(reference), "--json"], purpose).stdout)
