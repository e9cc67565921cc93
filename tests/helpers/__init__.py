"""What several test modules share (no test module imports another; ``tests/test_architecture.py`` checks it).

- :mod:`.corpus`: the real meshes of ``../shared/meshes`` (the one place their path is spelled);
- :mod:`.cli`: ``affinity`` run in the test's process (``run``) or in one of its own (``run_process``),
  small OBJ texts written into a test's folder;
- :mod:`.quads`: corner lists, OBJ text of separate quads, hand-built findings and a sample run;
- :mod:`.sarif`: validation against the official SARIF schema;
- :mod:`.nodes`: FIFOs and device nodes for output tests;
- :mod:`.generated_obj`: random valid OBJ files;
- :mod:`.split_reference`: the split's error by dense sampling (never the closed form);
- :mod:`.opengl_reference`: a second rasterizer, Mesa llvmpipe through OpenGL.
"""
