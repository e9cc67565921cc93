"""Mesh loaders: ``load(path) -> Mesh`` dispatching on the file extension."""
