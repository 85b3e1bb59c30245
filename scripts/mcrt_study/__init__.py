"""Error against run time of the renderer's configurations.

Runs the whole study with one command: for every Cornell scene, every
configuration of the renderer — light-sampling strategy (``area``,
``solid-angle``) × integrator (``mixture``: Shirley's mixture pdf, ``nee``:
next-event estimation, ``mis``: NEE with multiple importance sampling) ×
sample generator (``independent``, ``stratified``, ``sobol``) × light
selection (``--light-selects``; by default the scene's own) — and both
light-transport modes (``global``: the scene's max depth; ``direct``: max
depth 1), it renders a sweep of sample counts with several seeds, measures the
render time (``render_seconds`` from ``mcrt render --stats``: the rendering
alone, no process start, no I/O) and the error against a reference image
(``rmse``, ``mse``, ``relmse`` from ``mcrt diff --json``), then writes a CSV,
markdown tables, plots and a report.

Usage (from the repository root, with the virtual environment made by
scripts/setup.sh --python)::

    .venv/bin/python scripts/study.py                 # full study -> study-out/<UTC time>/
    .venv/bin/python scripts/study.py --quick         # a few minutes -> build/study-quick/
    .venv/bin/python scripts/study.py --quick --check # and verify the outputs
    .venv/bin/python scripts/study.py --out bench/results --overwrite-committed
                                                      # rewrite the committed report

    # your own scene file (a path, .json or .pbrt; a name without an extension is
    # looked up as scenes/NAME.json)
    .venv/bin/python scripts/study.py --scenes path/to/my_scene.json \
        --integrators nee --samplers sobol \
        --strategies area solid-angle projected-solid-angle auto

    # the triangle families, with pbrt-v4's strategy as the anchor
    .venv/bin/python scripts/study.py --scenes tri_size tri_distance tri_aspect tri_grazing \
        --integrators nee --samplers sobol --strategies area solid-angle \
        projected-solid-angle bilinear-solid-angle pbrt auto

    # many lights: the light selections against each other
    .venv/bin/python scripts/study.py --scenes many_lights --integrators nee \
        --samplers sobol --strategies area solid-angle \
        --light-selects power uniform bvh pbrt-bvh --ref-light-select bvh

    # choose what to run: every axis has its option
    .venv/bin/python scripts/study.py --scenes cornell_rect cornell_disk \\
        --strategies area solid-angle --integrators mixture mis \\
        --samplers independent sobol --depths global direct \\
        --spp 4 16 64 --seeds 1 2 3 --ref-spp 4096 --width 300 --height 300 \\
        --threads 2 --mcrt build/mcrt --out /tmp/study

Defaults (the full study): scenes cornell_rect, cornell_rect_large,
cornell_disk, cornell_disk_large (add cornell_materials with --scenes); both
strategies, all three integrators, all three samplers, both depth modes
(36 configurations and modes per scene, 144 over the four scenes); spp 8,
32, 128; seeds 1, 2, 3 (9 renders per configuration and mode: 1296 renders and
as many diffs); half the scenes' width and height (300x300 for the Cornell
scenes' 600x600: the same samples per pixel at a quarter of the cost;
``--width 600 --height 600`` for their own); the scenes' max depth
(``--max-depth`` overrides it for the global mode); a 4096 spp reference per
scene and depth mode (8 in all) rendered with seed 7919; all hardware threads.
About an hour on a 2-core machine that is otherwise idle (renders ~25 min,
references ~20 min, mcrt process start-up and image I/O ~10 min).
``--quick``: 48x48, spp 4, 8, 16, 32, one seed, integrators mixture and mis,
samplers independent and sobol, both depth modes, 1024 spp references, output
in build/study-quick (ignored by git); each of these can still be overridden.

Where a run writes. Without ``--out`` every run writes to a new directory,
study-out/<UTC start time>/ under the current directory (study-out/ holds a
.gitignore of '*', so git ignores it wherever it lies); the log's first line
names it, and ``--out`` naming it resumes that run or rebuilds its report
(``--report-only`` needs ``--out``). A directory that holds files tracked by
git (the committed results: bench/results/, bench/results/strategy_map/, ...)
is rewritten only with ``--overwrite-committed``; without it the command
writes nothing, prints one line and exits with status 2. The report links only
the figures git keeps beside it (where git would ignore a figure but keep the
report, the figure is written and named, not linked).

Generated scene families. ``--scenes`` also takes the name of a generated
family, meaning all its members, or of one member: size_rect, size_disk,
size_sphere (the Cornell box with its ceiling light a rectangle, disk or
sphere at 1/16, 1/4, 1, 2, 4, 8 times the seed light's area, equal radiance
times (projected) area; members size_rect_1of16 ... size_rect_x8) and distance
(the seed's rectangle over a large floor at heights 0.01 ... 10 times its size;
members distance_h0.01 ... distance_h10). The triangle families are pbrt-v4
files (the JSON format has no triangles): one emissive triangle over a large
floor beside a small cube, of equal power in every member: tri_size (the
equilateral triangle at 1/16 ... 8 times the reference's area; members
tri_size_1of16 ... tri_size_x8), tri_distance (heights 0.01 ... 10 times its
edge; tri_distance_h0.01 ... tri_distance_h10), tri_aspect (slivers of the
same area, base / height 1 ... 10^4 times the equilateral's; tri_aspect_a1 ...
tri_aspect_a10000) and tri_grazing (tilted until the cosine between its normal
and straight down is 1 ... 0.001, its plane nearly through the floor under it;
tri_grazing_c1 ... tri_grazing_c0.001). many_lights: the scenes of
bench/many_lights.py (N = 10 ... 10^5 small emitters of varied radiance over a
floor with boxes, many_lights_n10 ... many_lights_n100000, and an emissive
mesh of 12,800 triangles, many_lights_mesh), scaled to the same power. Their
scene files are written to OUT/scenes/ (NAME.json or NAME.pbrt) when the study
runs, byte-identical from run to run, so they are cached like scene files
(the files of 10^4 and 10^5 lights take seconds to make). See scenes.py for
their exact geometry.
With a family among the scenes the report plots, per family and depth mode,
each strategy's efficiency over area sampling against the light's solid
angle and tabulates where it crosses 1 (family_<family>_<mode>.png).
``--pixel-maps SCENE ...`` (default none) adds per-pixel efficiency maps
against area sampling, ``--pixel-map-seeds`` renders (default 8) at
``--pixel-map-spp`` (default the sweep's largest) per strategy in the report's
slice (pixelmaps.py; pixelmap_<scene>_<mode>.png and .npz).

Reference images. One reference per scene and depth mode (max depth), shared
by every strategy, integrator and sampler since they all converge to the same
image, rendered by the reference configuration: ``--ref-integrator`` (default
mis), ``--ref-sampler`` (default sobol) and ``--ref-strategy`` (default:
solid-angle when the mcrt binary supports it for that scene, else area) at
``--ref-spp``. References are cached in OUT/references/ under a key made of the
scene file's content, the resolution, spp, max depth, seed, strategy,
integrator and sampler (``--ref-key-binary`` adds a hash of the mcrt binary),
so they are rendered once; a reference made by mixture + independent has the
key of the earlier, single-integrator study, whose cache stays valid.

Resuming. Every finished point is written at once as its own file,
OUT/points/<hash>.json (by whichever process rendered it, through a temporary
name and a rename, so never half-written), and appended to OUT/results.csv;
a run with the same --out, and --report-only, first merge into the CSV the point files it lacks
(those made with the settings study_state.json records), so a crashed or
killed run loses no finished point. A run skips the points already there (a point is scene, strategy, integrator,
sampler, max depth, spp, seed). OUT/study_state.json remembers, per scene and
max depth, the settings the points were made with (scene content, resolution,
max depth, reference): when those change, the points of that scene and depth
are dropped and run again. ``--fresh`` discards all previous points
(references stay cached). A results.csv of the earlier format
(scene,strategy,spp,seed,seconds,rmse,mse,relmse) is read as integrator
mixture, sampler independent and the scene's max depth (how it was made) and
rewritten in the new format, as is one without the family columns or without
the light_select column (read as light selection default); a study_state.json
of the earlier version is carried over likewise.

Sweep order. For every seed and spp, every depth mode and configuration is
rendered in turn (the order of the configurations rotated from one point to
the next), so that a drift of the machine's speed affects all configurations
alike.

Where the renders run. References are rendered by the command itself, one at
a time, before a scene's sweep. The sweep's points run on an executor:
``--jobs 1`` (default) one after another in this process; ``--jobs N`` a pool
of N local processes, each render with --threads max(1, cores // N) unless
--threads is given; ``--backend dask --scheduler tcp://HOST:8786`` the workers
of a Dask distributed cluster, which need the mcrt binary at the same path and
OUT on shared storage (see executors.py). Rows enter the CSV in the sweep's
order whatever order the points finish in. Concurrent renders share the
machine; equal-time comparisons stay fair because the configurations are
rotated, so that each runs alongside the others alike.

Light selection. ``--light-selects`` adds mcrt's ``--light-select`` (how
next-event estimation chooses among several lights: power, uniform, bvh,
pbrt-bvh) as an axis of the configurations; ``default`` (the default) passes
none, so that the scene chooses (a pbrt-v4 file's lightsampler, else power).
It is a column of the CSV and of the report's tables (when the run names a
selection), part of a point's key, and the baseline takes the default
selection (or the first selected). ``--ref-light-select`` chooses the
references' (enters their cache key when it is not the default; bvh makes less
noisy references of many lights).

Unavailable strategies. A configuration that mcrt rejects as "not available
in this build", or as not available for that kind of scene file (exit status
2; for now ``--light-sampling auto`` on pbrt-v4 scenes), is skipped for that
scene and named in the report; the study goes on, and picks it up unchanged once mcrt supports it (a
reference that fell back to area sampling is then rendered again with
solid-angle sampling, and the points of its scene and depth with it). Any
other mcrt failure is reported too and makes the exit status 1.

Progress is shown on stderr as a plain-text bar with an estimate of the time
left. ``--report-only`` rebuilds tables, plots and report from the CSV
without rendering (without --spp or --seeds, for the spp values and seeds the
CSV holds). ``python scripts/study.py --help`` lists every option.

Analysis. The efficiency of a render is 1/(MSE × seconds); a configuration's
efficiency is the geometric mean of its renders' efficiencies over every spp
and seed of the sweep, compared with the baseline (area, mixture, independent)
of the same scene and depth mode. The tables give, per scene and depth mode,
the efficiency of every configuration and its ratio to the baseline (the best
marked), the MSE of every configuration interpolated at a few equal time
budgets, and the log-log slope of RMSE against spp (−0.5 for Monte Carlo;
steeper for a quasi-Monte-Carlo sampler where the integrand is smooth enough,
e.g. direct lighting). The earlier area-vs-solid-angle tables and plots are
kept for the slice integrator mixture, sampler independent, global depth (or
the first selected integrator, sampler and mode when those are not run).

Outputs (in OUT):
    results.csv          scene,strategy,integrator,sampler,max_depth,spp,seed,
                         seconds,rmse,mse,relmse,family,family_param,
                         light_solid_angle,light_select (max_depth: the value
                         passed to mcrt, 1 in the direct mode; family and
                         family_param empty for scene files; the solid angle
                         (sr) of the scene's first light from the box's centre
                         (278, 278, 279.5), for the distance and triangle
                         families from the floor point under the light, for
                         many_lights the median over its emitting triangles
                         from the floor point (0, 0, 0.5), empty when not
                         computed, as for pbrt-v4 files of one's own;
                         light_select: default when no --light-select was passed)
    tables.md            the markdown tables
    README.md            the report: machine, the renderer's commit and the
                         mcrt binary's sha256, command line, date, tables,
                         sampler costs and the plots
    efficiency_global.png, efficiency_direct.png  (efficiency per configuration
                         and scene, grouped bars, log scale)
    rmse_vs_spp.png, time_vs_spp.png, rmse_vs_time.png, efficiency.png,
    rmse_diff_SCENE.png  (the area-vs-solid-angle slice; RMSE area - RMSE
                         solid-angle per spp)
    samplers.json        raw output of mcrt_bench_samplers
    references/          cached reference images (EXR) and their metadata
    scenes/              the scene files of the generated families selected

``--check`` verifies the outputs afterwards (files exist, CSV columns, every
configuration has its points in every scene and depth mode, RMSE decreasing
with spp: negative log-log slope per scene, depth mode and configuration,
efficiency tables and plots present) and exits 1 when a check fails; the test
suite runs ``--quick --check``.

Code (this package; scripts/study.py is the command's entry point and calls
cli.main):
    config.py       constants, the types (Config, SceneInfo, Settings, ...),
                    the command line and its defaults
    scenes.py       scene files by name or path; generated families
    pbrt_families.py  the pbrt-v4 families (triangles, many lights); a pbrt-v4
                    file's resolution and depth
    many_lights_scenes.py  the many-light scenes (bench/many_lights.py's too)
    solid_angles.py the solid angles of lights
    mcrt.py         running mcrt: render (with its time), diff
    references.py   reference images and their cache keys
    results.py      results.csv and study_state.json (resuming)
    runner.py       the sweep, and the sampler benchmark
    executors.py    where the sweep's points run: this process, a local process
                    pool, a Dask cluster (--jobs, --backend, --scheduler)
    points.py       one point on a worker (render, diff) and its point file;
                    merging point files into results.csv
    analysis.py     efficiency, standard errors, equal-time interpolation,
                    convergence slopes, crossovers (pure; no files)
    report.py       markdown tables and README.md (the renderer's commit, the
                    machine, links only to figures git keeps)
    plots.py        the figures (matplotlib)
    check.py        --check
    cli.py          main()
    util.py         hashes, atomic writes, logging, the progress bar
    summary_figure.py  docs/images/summary.png from the committed results
                    (cd scripts && ../.venv/bin/python -m mcrt_study.summary_figure)
    tests/          unit tests of the analysis on synthetic data, of the cache
                    keys, of the scene families, of the sweep on its
                    executors with point files (a fake render, no mcrt), of
                    where a run writes and of the report's provenance and links:
                    .venv/bin/python -m unittest discover -s scripts/mcrt_study/tests -t scripts
"""
