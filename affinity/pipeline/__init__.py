"""Running the check over many files: collecting them, checking each (in parallel or on a cluster), the
baseline and the result cache.

- :mod:`.files`: the paths given, directories expanded into their mesh files;
- :mod:`.check`: one file's check (``check_file``, never raising for bad input)
  and many files' (``check_files``, ``--jobs``);
- :mod:`.workers`: the local worker processes of ``--jobs``, which end with the run;
- :mod:`.baseline`: today's findings recorded, so later runs fail only on new ones;
- :mod:`.cache`: the results of unchanged files, kept between runs (``AFFINITY_CACHE_DIR``, ``--no-cache``);
- :mod:`.cluster`: the files checked on a Dask cluster (``--scheduler``).
"""
