"""The HTML report (``affinity report``): one self-contained page per run.

The pipeline, one module per step:

- :mod:`.demo` — the built-in scenes and the view each is shown from;
- :mod:`.build` — collects, per mesh, the lint with every quad's scores
  (one pass, ``affinity.lint.lint_pass``), the renders, the 3-D overview and
  the close-ups (``affinity.draw.closeup``), each step returning its values;
- :mod:`.stiffness` — the numerical stability of the hybrid's mvc pixels;
- :mod:`.sections` — one function per section, each deciding from the
  collected data whether it appears or is left out with a one-line reason;
- :mod:`.page` — renders the sections with the Jinja2 templates (autoescaped);
- :mod:`.places`, :mod:`.uvlayout` — the flagged places and the
  texture-space view;
- :mod:`.images`, :mod:`.charts` — pictures, colour bars and inline SVG charts.

Nothing heavy is imported here: Pillow, Jinja2, matplotlib and pyvista are
imported by the functions that use them.
"""

#: Size of the renders and the 3-D overview (``--size``), close-ups per mesh (``--max-views``) and the most faces
#: a close-up's place holds (``--place-faces``: an eye takes in a few dozen): here, so the command line reads them
#: without importing the builder.
RENDER_SIZE = (480, 360)
MAX_VIEWS = 6
PLACE_FACES = 24
