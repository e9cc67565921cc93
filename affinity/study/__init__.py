"""The error-against-run-time study (``affinity bench``, issue 10).

One module per job:

- :mod:`.cases` — the scenes: the paper's figures rebuilt, the nonplanar quad
  strip, and real meshes (``../shared/meshes`` when present), each with its view;
- :mod:`.sweep` — one scene: every method and hybrid setting drawn, timed and
  compared with the ``exact`` reference; the Pareto front;
- :mod:`.metrics` — attribute error (RMS, p99, max), PSNR, SSIM, crease;
- :mod:`.timing` — warm-up, interleaved repeats, median and spread, machine facts;
- :mod:`.tables`, :mod:`.charts` — the CSV, the markdown summary and the PNG charts;
- :mod:`.run` — all of it for a list of cases, into a folder.

Nothing heavy is imported here; matplotlib only by the charts.
"""
