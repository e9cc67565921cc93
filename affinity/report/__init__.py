"""The HTML report (``affinity report``): one self-contained page per run.

The pipeline, one module per step:

- :mod:`.demo` — the built-in scenes and the view each is shown from;
- :mod:`.build` — collects, per mesh, the lint, every quad's scores
  (:mod:`.scores`), the renders and the 3-D overview;
- :mod:`.sections` — one function per section, each deciding from the
  collected data whether it appears or is left out with a one-line reason;
- :mod:`.page` — renders the sections with the Jinja2 templates (autoescaped);
- :mod:`.images`, :mod:`.charts`, :mod:`.errors` — pictures, charts and
  per-pixel errors for the sections.

Nothing heavy is imported here: Pillow, Jinja2, matplotlib and pyvista are
imported by the functions that use them.
"""
