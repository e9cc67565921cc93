"""A run split into shards for CI matrices and render farms, and the shards' results merged back into one.

- :mod:`.selection`: which files shard K of N checks (``affinity check --shard K/N``), and the record
  each shard's result carries so a merge can tell whether the shards make up one run;
- :mod:`.results`: a ``--format json`` result read back into the reports that made it;
- :mod:`.merge`: the shards' results checked against each other and joined into the reports of one run
  (``affinity merge``), which every output format then writes as if one run had checked every file.
"""
