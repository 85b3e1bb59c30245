"""The timed renders, interleaved: for each seed and spp every renderer runs
once, in turn (A, B, C, ..., then reversed on the next seed), so that the
machine's drift hits them alike. mcrt's time is render_seconds of --stats;
Mitsuba's is the wall time of mi.render alone. Each MSE is against that
renderer's own reference."""
import numpy as np

from . import images, translate
from .mitsuba_run import Mitsuba


def probe(mcrt, scene, configs, out, log):
    """Fails fast, before any long render, on flags the binary does not take."""
    for name, flags, text in configs:
        try:
            mcrt.render(scene, out / "probe.exr", 1, 0, 8, 8, flags, purpose="probe")
        except RuntimeError as e:
            raise SystemExit(f"mcrt configuration {name} ({text!r}) does not run: {e}")
    (out / "probe.exr").unlink(missing_ok=True)
    log("mcrt configurations: " + ", ".join(f"{n}={t!r}" for n, _, t in configs) + ": ok")


def interleaved(a, s, mcrt, mi, configs, log):
    name, (w, h), tmp = s["name"], s["size"], a.out / "tmp"
    items = [("mcrt", f"mcrt:{n}", f) for n, f, _ in configs]
    items += [("mitsuba", f"mitsuba:{smp}", smp) for smp in a.samplers]
    scenes = {smp: mi.load(translate.describe(s["scene"], w, h, sampler=smp, max_depth=a.max_depth),
                           (name, smp)) for smp in a.samplers}
    for sc in scenes.values():  # untimed warm-up: first-call costs out of the timings
        mi.render(sc, min(a.spp), 0)
    runs = []
    for k, seed in enumerate(range(1, a.seeds + 1)):
        for spp in a.spp:
            for renderer, config, what in (items if k % 2 == 0 else items[::-1]):
                r = {"scene": name, "renderer": renderer, "config": config, "spp": spp, "seed": seed,
                     "size": [w, h]}
                if renderer == "mcrt":
                    out = tmp / f"{name}-{config.replace(':', '-')}.exr"
                    st = mcrt.render(s["path"], out, spp, seed, w, h, what, a.max_depth,
                                     purpose=f"measurement {config}")
                    img = images.read_exr(out)
                    r["mse_numpy"] = images.mse(img, s["mc_ref"])
                    if images.READER == "OpenImageIO":
                        r["mse"] = r["mse_numpy"]
                    else:  # as asked: mcrt's own `diff` when OpenImageIO's Python module is absent
                        r["mcrt_diff"] = mcrt.diff(out, s["mc_path"], purpose="measurement MSE")
                        r["mse"] = r["mcrt_diff"]["mse"]
                    out.unlink()
                    r.update(seconds=st["render_seconds"], flags=what, command=st["command"],
                             ref_noise_mse=s["mc_meta"]["noise_mse"], nonfinite=st.get("nonfinite_samples"))
                else:
                    img, sec, cpu = mi.render(scenes[what], spp, seed, busy=r)
                    r.update(seconds=sec, cpu_seconds=cpu, cpu_over_wall=cpu / sec, sampler=what,
                             mse=images.mse(img, s["mi_ref"]), ref_noise_mse=s["mi_meta"]["noise_mse"],
                             command=Mitsuba.call_text(what, spp, seed, mi.variant),
                             nonfinite=int(np.count_nonzero(~np.isfinite(img))))
                r["mse_minus_ref_noise"] = r["mse"] - r["ref_noise_mse"]
                r["efficiency"] = 1 / (r["mse"] * r["seconds"])
                log(f"{name} seed {seed} spp {spp:5d} {config:24s} {r['seconds']:8.3f} s  "
                    f"MSE {r['mse']:.4e}  eff {r['efficiency']:.4g}")
                runs.append(r)
    return runs


def setup_lines(a, res):
    runs, m = res["runs"], res["machine"]
    mc = [r for r in runs if r["renderer"] == "mcrt"]
    mis = [r for r in runs if r["renderer"] == "mitsuba"]
    dev = max((abs(r["mse_numpy"] / r["mse"] - 1) for r in mc if r["mse"]), default=None)
    cpu = [r["cpu_over_wall"] for r in mis]
    busy = sorted({r.get("busy_threads") for r in mis if r["seconds"] > 0.2} - {None})
    return {
        "Machine": f"{m['cpu']}, {m['cores']} cores; repository commit {m['git_commit']}; {m['date']}",
        "Bench": f"`{res['bench_command']}`",
        "Images": f"{a.size} px wide, spp {', '.join(map(str, a.spp))}, seeds 1..{a.seeds}, "
                  f"references 2 x {a.ref_spp // 2} spp (seeds {images.REF_SEEDS[0]}, {images.REF_SEEDS[1]}; "
                  f"Mitsuba's with its {a.mitsuba_ref_sampler} sampler)",
        "mcrt": f"`{res['mcrt']['copied_from']}`, run as its copy `{res['mcrt']['binary']}` (sha256 {res['mcrt']['sha256'][:12]}), --threads {a.threads}, "
                f"time = render_seconds of --stats; reference flags: `{res['mcrt']['reference_flags'] or '(none)'}`",
        "Mitsuba": f"{res['mitsuba_version']} (drjit {res['drjit_version']}), {res['mitsuba_variant']}, "
                   f"drjit.thread_count() = {res['mitsuba_threads']}, time = wall time of mi.render; "
                   f"CPU/wall of its renders {min(cpu, default=0):.2f}-{max(cpu, default=0):.2f}, "
                   f"threads busy in renders > 0.2 s: {busy}",
        "Load": f"load average before the run {m['load_before']}, after {m.get('load_after')} "
                "(the machine is shared: other processes change the timings)",
        "Depth": "mcrt max_depth D (scattering events) = Mitsuba path max_depth D+1 (path vertices); "
                 "Mitsuba rr_depth default (5), hide_emitters false",
        "MSE": f"mean over pixels and 3 channels of (v-r)^2; mcrt images read with {images.READER}"
               + (f"; numpy MSE vs `mcrt diff` mse: max relative difference {dev:.1e}" if dev is not None else ""),
    }


def command_summary(res, commands):
    """The bench's command, one mcrt command of each purpose, the Mitsuba calls."""
    lines = [res["bench_command"]]
    first = {}
    for purpose, cmd in commands:
        first.setdefault(purpose, cmd)
    for purpose, cmd in first.items():
        lines.append(f"# mcrt, {purpose}:")
        lines.append(cmd)
    for smp in res["settings"]["samplers"]:
        lines.append(f"# Mitsuba, {smp}: scene = mi.load_dict(...) of OUT/xml/SCENE.xml with the film and "
                     "sampler below, then timed:")
        lines.append(Mitsuba.call_text(smp, "SPP", "SEED", res["mitsuba_variant"]))
    return lines
