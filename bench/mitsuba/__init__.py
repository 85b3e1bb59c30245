"""bench.mitsuba: mcrt's efficiency against Mitsuba 3's path tracer on the
same scenes. Run `python -m bench.mitsuba --help` from the repository root;
see README.md in this folder."""
