"""Textures for the lint (core layer, below ``draw/``): decoding under a pixel budget, bilinear
filtering, min/max pyramids, and the visible reading of Q101 (design.md, "The visible reading").

Finding which textures a mesh binds is the loaders' (:mod:`affinity.loaders.texturemaps`),
reading image sizes from headers too (:mod:`affinity.loaders.imagesize`). Pillow is imported
only here, and only when a checked mesh binds a texture whose header is readable.
"""
