"""Which files shard K of N checks, and the record that ties a shard's result to its run.

A file belongs to shard ``1 + h mod N``, ``h`` the 64-bit BLAKE2b hash of its path
relative to the project root (with ``/`` separators): the folder of the
configuration file governing the working directory (``affinity.toml`` or
``pyproject.toml``, or ``--config FILE``'s folder), else the working directory.
The same file lands in the same shard on every machine and every run, whatever
the other files are, so each shard's result cache stays warm, and whatever the
files' sizes (a checkout without ``git lfs pull`` or with CRLF line ends must not
move files between shards). The shards of a run are disjoint and cover it.

Each shard's result carries a :class:`ShardRecord`: K, N, the count and digest of
the whole run's file list (in run order) and the positions of the shard's files
in it, so ``affinity merge`` can restore the run's order and tell a missing,
repeated or foreign shard.
"""

from __future__ import annotations

import argparse
import hashlib
import os
from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Shard:
    """Shard ``index`` (1-based) of ``count``."""

    index: int
    count: int

    def __str__(self) -> str:
        return f"{self.index}/{self.count}"


def parse_shard(text: str) -> Shard | AutoShard:
    """An argparse ``type`` for ``--shard K/N`` (1 <= K <= N), ``--shard auto`` or ``--shard auto/N``.

    ``auto`` is resolved later, from the environment (:func:`shard_from_environment`).

    >>> parse_shard("2/4")
    Shard(index=2, count=4)
    >>> parse_shard("auto/8")
    AutoShard(count=8)
    """
    index, _, count = text.partition("/")
    if index == AUTO and (not count or (count.isdigit() and int(count) >= 1)):
        return AutoShard(int(count) if count else None)
    if not (index.isdigit() and count.isdigit()) or not 1 <= int(index) <= int(count):
        raise argparse.ArgumentTypeError(f"not a shard: {text!r} (use K/N with 1 <= K <= N, e.g. 2/4, "
                                         "or auto, auto/N)")
    return Shard(int(index), int(count))


AUTO = "auto"

#: Kubernetes Indexed Jobs: the pod's 0-based completion index (the Job's completions are not exposed).
K8S_INDEX = "JOB_COMPLETION_INDEX"
#: The shard count beside ``JOB_COMPLETION_INDEX`` when ``--shard auto/N`` does not give it.
SHARD_COUNT = "AFFINITY_SHARD_COUNT"
#: GitLab CI's ``parallel`` jobs: the 1-based node index and the node count.
GITLAB_INDEX, GITLAB_TOTAL = "CI_NODE_INDEX", "CI_NODE_TOTAL"


@dataclass(frozen=True)
class AutoShard:
    """``--shard auto[/N]``: the shard index (and count, unless ``count``) from the farm's environment."""

    count: int | None = None


def shard_from_environment(auto: AutoShard, environ: Mapping[str, str]) -> Shard:
    """The shard ``--shard auto[/N]`` names in ``environ``; ValueError (its message one line) when none.

    Kubernetes Indexed Jobs: K = ``JOB_COMPLETION_INDEX`` + 1 (0-based there), N from ``auto/N``, else
    ``AFFINITY_SHARD_COUNT``. GitLab: K = ``CI_NODE_INDEX``, N = ``CI_NODE_TOTAL`` (both 1-based). GitHub
    Actions sets neither: spell the shard out there (``--shard ${{ matrix.shard }}/N``).

    >>> shard_from_environment(AutoShard(4), {"JOB_COMPLETION_INDEX": "0"})
    Shard(index=1, count=4)
    >>> shard_from_environment(AutoShard(), {"CI_NODE_INDEX": "3", "CI_NODE_TOTAL": "5"})
    Shard(index=3, count=5)
    """
    if K8S_INDEX in environ:
        index = _whole(environ, K8S_INDEX) + 1
        if auto.count is not None:
            count = auto.count
        elif SHARD_COUNT in environ:
            count = _whole(environ, SHARD_COUNT)
        else:
            raise ValueError(f"{K8S_INDEX} is set but not the shard count: use --shard auto/N or set {SHARD_COUNT}")
        where = f"{K8S_INDEX}={index - 1}"
    elif GITLAB_INDEX in environ or GITLAB_TOTAL in environ:
        index, count = _whole(environ, GITLAB_INDEX), _whole(environ, GITLAB_TOTAL)
        if auto.count is not None and auto.count != count:
            raise ValueError(f"--shard auto/{auto.count} but {GITLAB_TOTAL}={count}")
        where = f"{GITLAB_INDEX}={index}"
    else:
        raise ValueError(f"--shard auto: no shard index in the environment ({K8S_INDEX} of a Kubernetes Indexed "
                         f"Job, or {GITLAB_INDEX} and {GITLAB_TOTAL}); elsewhere give --shard K/N")
    if not 1 <= index <= count:
        raise ValueError(f"--shard auto: {where} is not a shard of {count}")
    return Shard(index, count)


def _whole(environ: Mapping[str, str], name: str) -> int:
    """The whole number in ``environ[name]``; ValueError naming the variable when it is missing or not one."""
    text = environ.get(name, "").strip()
    if not text.isdigit():
        raise ValueError(f"--shard auto: {name}={environ.get(name, '')!r} is not a whole number"
                         if name in environ else f"--shard auto: {name} is not set")
    return int(text)


def run_key(path: str, root: str) -> str:
    """``path`` relative to ``root`` with ``/`` separators: the name a shard hashes and the digest lists.

    A path on another drive than ``root`` (Windows) has no relative form: its absolute path is used.
    """
    absolute = os.path.abspath(path)
    try:
        relative = os.path.relpath(absolute, root)
    except ValueError:
        relative = absolute
    return relative.replace(os.sep, "/")


def shard_of(key: str, count: int) -> int:
    """The 1-based shard of the file named ``key`` (:func:`run_key`) among ``count`` shards.

    >>> shard_of("props/crate.obj", 1)
    1
    """
    digest = hashlib.blake2b(key.encode("utf-8", "surrogatepass"), digest_size=8).digest()
    return 1 + int.from_bytes(digest, "big") % count


def run_digest(keys: list[str]) -> str:
    """The SHA-256 of the run's file list (:func:`run_key` of each, in run order), as hex."""
    joined = "\0".join(keys)  # NUL cannot occur in a path
    return hashlib.sha256(joined.encode("utf-8", "surrogatepass")).hexdigest()


@dataclass(frozen=True)
class ShardRecord:
    """What a shard's result says about its place in the run (JSON ``"shard"``).

    ``index`` of ``of`` shards; ``run_files`` and ``run_digest`` the count and
    :func:`run_digest` of the whole run's file list; ``positions`` the 0-based
    place in that list of each of the shard's files, in the shard's order;
    ``baseline`` whether the shard was checked against a baseline (the merged
    result then counts new findings); ``version`` the tool's.
    """

    index: int
    of: int
    run_files: int
    run_digest: str
    positions: list[int]
    baseline: bool
    version: str


def select_shard(paths: list[str], shard: Shard, root: str, baseline: bool = False) -> tuple[list[int], ShardRecord]:
    """The positions in ``paths`` (the whole run's files, in run order) of shard ``shard``'s files, rising,
    and the record its result carries; ``root`` is the project root the paths are hashed relative to."""
    from .. import __version__

    keys = [run_key(path, root) for path in paths]
    positions = [i for i, key in enumerate(keys) if shard_of(key, shard.count) == shard.index]
    record = ShardRecord(shard.index, shard.count, len(keys), run_digest(keys), positions, baseline, __version__)
    return positions, record
