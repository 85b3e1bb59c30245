"""Black-box fuzzing of the ``mcrt`` executable.

Usage (from the repository root; standard library only, any Python >= 3.11)::

    python3 tests/fuzz.py --mcrt build/mcrt --quick --out /tmp/fuzz \\
        --report /tmp/fuzz/report.json --markdown /tmp/fuzz/report.md
    python3 tests/fuzz.py --mcrt build/mcrt --mutations 3000 --out /tmp/fuzz-long --check
    python3 tests/fuzz.py --mcrt build/mcrt --only ply/nan-in-nx --out /tmp/f   # replay cases
    python3 tests/fuzz.py --mcrt build/mcrt --list                              # list case ids

The contract under test (docs/cli.md, /work/shared/spec/*.md)
--------------------------------------------------------------
Bad input gives exactly one line on stderr, starting with ``mcrt: ``,
naming the file (or flag, or image) and the reason, exit status 2, and no
output created or touched (outputs are written to a temporary name beside
the target and renamed into place, so no temporary may be left behind).
Good input renders (exit 0).  A crash, an abort, a hang, a memory blow-up
or non-finite radiance samples are bugs.

Method
------
Every case is a directory of input files plus a command.  The runner writes
the files under ``OUT/cases/<case-id>/`` (scenes, PLY meshes, images,
included files; FIFOs made with os.mkfifo; symlinks to /dev/zero,
/dev/urandom, /dev/null; directories where a file is expected; gzip bombs
built from one 64 MiB member of zeros compressed once per run and
concatenated), pre-creates the outputs (``out.png``, ``stats.json``,
``out.csv``) with the sentinel ``b"sentinel"``, snapshots the directory,
and runs mcrt there (cwd = the case directory) in a new session with
``--threads 1``.  The default command is::

    mcrt render SCENE -o out.png --width 8 --height 8 --spp 1 --threads 1 --quiet --stats stats.json

(cases that test those flags change them; ``mcrt samples ... -o out.csv``
and ``mcrt diff A B`` cases exist too).  The worker thread is the watchdog:
it polls the child every ~20 ms (os.wait4 with WNOHANG, /proc/PID/status
VmRSS) and kills the process group past the timeout or past twice the
memory limit; ``ru_maxrss`` from wait4 gives the peak RSS at the end.
stdout and stderr go to ``OUT/logs/<case-id>.stdout|.stderr``.

Case ids are ``family/name``.  Every case is rebuilt from (seed, id) alone:
a case that needs randomness draws it from ``random.Random`` seeded by a
hash of the run's seed and its id (``model.case_rng``), never from a shared
stream; ``--only ID`` replays it (a mutation id beyond ``--mutations`` is
rebuilt too).

Structural families (``cases.py``; each varies one thing of a tiny base
scene that renders in ~0.3 s at 8x8, 1 spp): syntax, include, files,
camera, geometry, lights, ply, texture, flags, json.  A case may declare
the class it must end in (for instance a BOM, CR-only or CRLF file, a
uniform Scale 1e-30 camera, every light black under every light selection,
a FLT_MAX vertex beside normals, a stiff but valid light: MUST render; a
negative light scale, NaN in PLY normals or uv, a --seed no 64-bit value
holds: MUST be refused).  Random mutations (``mutate.py``) of every shipped
scene (scenes/pbrt/**.pbrt with the files they use, scenes/*.json): 1-4
operators on pbrt tokens, JSON values or binary aux files, rendered with a
random light strategy, light selection, integrator and sampler.

Classes (``classify.py``)
-------------------------
  rendered        exit 0 and the outputs are right: the image replaced by a
                  real PNG/EXR/PPM, stats.json valid JSON with
                  nonfinite_samples == 0 (samples: a finite CSV with its
                  header; diff: the four values)
  clean_refusal   exit 2, stderr exactly one line (no CR, no control
                  characters), starting with "mcrt: ", at most 1000
                  characters, naming the scene, the corrupted file, the flag
                  or the image, no library text (libpng, what(), std::, ...),
                  nothing on stdout, the sentinels intact (same content,
                  inode and mtime), no new file in the case directory
  dirty_refusal   exit 1 or 2 (or another status) breaking any rule above;
                  the reasons say which
  crash           killed by a signal, exit 134/136/139, "terminate called",
                  or (--sanitizer) an AddressSanitizer/UBSan/LeakSanitizer
                  report
  hang            still running at the timeout (the process group is killed)
  memory          peak RSS above the limit
  nonfinite       exit 0 but nonfinite_samples > 0, the stderr line
                  "non-finite radiance samples were dropped", or a
                  non-finite value in samples' CSV or diff's output
  bad_output      exit 0 without the right outputs (not written, not an
                  image, invalid statistics, a temporary file left behind)
  unexpected      an ok class other than the one the case declared (the
                  reasons say what was expected)
ok = rendered or clean_refusal; everything else is reported.

Options (tests/fuzz.py)
-----------------------
  --mcrt PATH        the executable (required; waited for while it is
                     missing or being rewritten)
  --out DIR          work directory: cases/ and logs/; kept for every case
                     that is not ok, deleted for ok ones unless --keep
  --seed N           seed of the random cases (default 1)
  --mutations N      random-mutation cases (default 300)
  --quick            every structural case + cli.QUICK_MUTATIONS mutations,
                     timeout 5 s unless --timeout is given (fixed counts,
                     never a time budget): 744 cases in 95 s with --jobs 2
                     on the idle 2-core machine, 144 s with a compiler
                     running beside it (each mcrt run costs ~0.25 s of
                     start-up, so the count sets the time)
  --jobs J           parallel cases (default 2)
  --timeout S        seconds before a case is a hang (default 30)
  --mem-limit BYTES  peak RSS limit (default 2 GiB; killed at twice that)
  --report FILE      JSON: counts per class and family, findings (not-ok
                     cases grouped by class and masked first stderr line),
                     every not-ok case (id, family, command, exit status,
                     first 300 characters of stderr, reproducer directory),
                     and [id, class, seconds] of every case
  --markdown FILE    the same as Markdown tables
  --check            exit status 1 if any case is not ok
  --only PREFIX      run only the cases whose id starts with PREFIX
  --list             list the case ids and exit
  --keep             keep the directories and logs of ok cases too
  --sanitizer        ASan/UBSan build: sanitizer reports are crashes, the
                     timeout x5, the memory limit x4

Modules
-------
  model.py      Case, file entries, case_rng
  artifacts.py  base scenes, PNG/PFM/EXR/PLY writers, gzip and the bomb
  cases.py      the structural families
  mutate.py     the random mutations
  runner.py     materialising a case, running it under the watchdog
  classify.py   the classes
  report.py     console summary, JSON and Markdown reports, findings
  cli.py        the command line
"""
