"""Where results go and what is said about them: the one output-folder policy of every
command, tables, ``metadata.json``, warnings and notes.

The policy (:func:`check`, applied by ``emc``'s ``main`` to every command with ``--out`` before
anything runs, and :func:`claim`, where the command starts writing):

- ``--out`` must be a folder that can be written: a file, or a place that cannot be created or
  written, is a one-line error.
- A folder whose ``metadata.json`` says it holds another command's results, or the same
  command's with other settings, is refused unless ``--overwrite`` is given; ``--overwrite``
  removes the files that run wrote (``metadata.json`` lists them as ``written``) before this
  one starts.
- A folder of the same command with the same settings is written again; a study continues from
  the evaluations stored there, and says so.
- One run writes a folder at a time: a second run is refused with the first's process id.
"""

from __future__ import annotations

import datetime
import json
import os
import pathlib
import platform
import re
import sys
import time
from importlib import metadata as importlib_metadata

from .errors import UsageError
from .fmu import file_sha256, start_value

# Options that change where or how fast results are made, not what they are.
NOT_SETTINGS = {"out", "quiet", "workers", "scheduler", "serial", "overwrite", "func",
                "command_line", "out_policy", "out_claim"}
LOCK_NAME = ".emc.lock"


def safe_name(signal: str) -> str:
    """A signal's name as a file name: ``steeringWheel.a[3]`` -> ``steeringWheel.a3``."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", re.sub(r"\[(\d+)\]", r"\1", signal)).strip("_")


def save(table, path: str):
    """A table as CSV, or as Parquet where ``path`` ends in ``.parquet``."""
    if str(path).endswith(".parquet"):
        table.to_parquet(path, index=False)
    else:
        table.to_csv(path, index=False)


def run_settings(args) -> dict:
    """The options that decide a command's results, as JSON values."""
    settings = {k: v for k, v in vars(args).items()
                if k not in NOT_SETTINGS and not k.startswith("_") and not callable(v)}
    return json.loads(json.dumps(settings, default=str))


def written_files(out: pathlib.Path, args) -> list[str]:
    """The files of ``out`` this run wrote (changed since it claimed the folder)."""
    claim_ = getattr(args, "out_claim", None)
    since = claim_.started if claim_ is not None else 0.0
    return sorted(str(p.relative_to(out)) for p in out.rglob("*")
                  if p.is_file() and p.name not in (LOCK_NAME, "metadata.json")
                  and p.stat().st_mtime >= since - 1.0)


class Claim:
    """A result folder held by this run: its lock released on :meth:`release`."""

    def __init__(self, path: pathlib.Path, lock, started: float):
        self.path = path
        self.lock = lock
        self.started = started

    def release(self):
        if self.lock is not None:
            self.lock.close()
            self.lock = None


def _lock(path: pathlib.Path):
    """The folder's lock file, held exclusively (None where the system has no locks)."""
    try:
        # Deferred: fcntl exists on POSIX systems only.
        import fcntl
    except ImportError:  # not POSIX: the folder is not locked
        return None
    lock = open(path / LOCK_NAME, "a+")
    try:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        lock.seek(0)
        holder = lock.read().strip() or "unknown"
        lock.close()
        raise UsageError(f"--out {path}: another emc run (process {holder}) is writing this "
                         "folder; wait for it to end, or use another folder") from None
    lock.seek(0)
    lock.truncate()
    lock.write(f"{os.getpid()}\n")
    lock.flush()
    return lock


def _previous_run(path: pathlib.Path) -> tuple[str | None, dict | None] | None:
    """(command, settings) of the results in ``path`` (None: no metadata.json)."""
    meta = path / "metadata.json"
    if not meta.exists():
        return None
    try:
        record = json.loads(meta.read_text())
        run = record.get("run") or {}
        command = run.get("command")
        if command is None and record.get("command"):
            command = record["command"][1]
        return command, run.get("settings")
    except (OSError, ValueError, AttributeError, IndexError, TypeError):
        return "unknown (its metadata.json is damaged)", None


def _differences(before: dict | None, now: dict) -> str:
    if before is None:
        return "other settings"
    keys = sorted(k for k in set(before) | set(now) if before.get(k) != now.get(k))
    shown = ", ".join(f"{k}: {before.get(k)!r} there, {now.get(k)!r} here" for k in keys[:3])
    return "other settings (" + shown + (", …" if len(keys) > 3 else "") + ")"


def _remove_previous(path: pathlib.Path):
    """Removes what the run recorded in ``path``'s metadata.json wrote, and the record."""
    meta = path / "metadata.json"
    try:
        files = json.loads(meta.read_text()).get("written") or []
    except (OSError, ValueError, AttributeError):
        files = []
    for name in list(files) + ["evaluations.jsonl", "metadata.json"]:
        target = (path / name).resolve()
        if target.is_file() and path.resolve() in target.parents:
            target.unlink()


def _problem(path: pathlib.Path, args) -> str | None:
    """Why ``path`` may not take this run's results (None: it may)."""
    previous = _previous_run(path) if path.is_dir() else None
    if previous is None:
        return None
    command, settings = previous
    now = run_settings(args)
    if command != args.command:
        return f"holds the results of emc {command}"
    if settings != now:
        return f"holds emc {command} results of {_differences(settings, now)}"
    return None


def check(args):
    """The output-folder policy (module doc) for ``args.out``, read only: run before anything
    else, so that a refused folder costs nothing and nothing is written."""
    path = pathlib.Path(args.out)
    if path.exists() and not path.is_dir():
        raise UsageError(f"--out {path}: a file, not a folder (results are written into a "
                         "folder)")
    existing = path
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        where = "the folder" if existing == path else f"{existing}, where it would be created,"
        raise UsageError(f"--out {path}: {where} cannot be written")
    problem = _problem(path, args)
    if problem and not getattr(args, "overwrite", False):
        raise UsageError(f"--out {path} {problem} (see its metadata.json): use another folder, "
                         "or --overwrite to replace them")


def claim(args) -> pathlib.Path:
    """The result folder, created and held by this run (until ``emc`` ends, which releases
    ``args.out_claim``) when a command is about to write: checked again under the folder's
    lock, the previous run's files removed if ``--overwrite`` replaces them, a study's
    continuation said."""
    path = pathlib.Path(args.out)
    check(args)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise UsageError(f"--out {path}: cannot create the folder ({error.strerror})") from None
    started = time.time()
    lock = _lock(path)
    try:
        problem = _problem(path, args)
        if problem and not getattr(args, "overwrite", False):
            raise UsageError(f"--out {path} {problem} (see its metadata.json): use another "
                             "folder, or --overwrite to replace them")
        if problem:
            _remove_previous(path)
        elif args.out_policy == "resume" and (path / "metadata.json").exists():
            print(f"note: {path} holds this study with the same settings: it continues from "
                  "the evaluations stored there", file=sys.stderr)
    except BaseException:
        if lock is not None:
            lock.close()
        raise
    args.out_claim = Claim(path, lock, started)
    return path


def warn(lines: list[str]):
    for line in lines:
        print(f"warning: {line}", file=sys.stderr)


def warn_cases(per_case: list[tuple[str, list[str]]]):
    """Each warning once: unlabelled if every case has it, else with the cases it concerns."""
    seen: dict[str, list[str]] = {}
    for label, lines in per_case:
        for line in lines:
            seen.setdefault(line, []).append(label)
    everyone = len(per_case)
    for line, labels in seen.items():
        if len(labels) == everyone or not any(labels):
            warn([line])
        else:
            warn([f"case {', '.join(repr(x) for x in labels)}: {line}"])


def fmu_warnings_summary(lines: list[str], shown: int = 5):
    """The FMU's warnings of successful points, each distinct message once."""
    distinct = list(dict.fromkeys(lines))
    if not distinct:
        return
    print(f"warning: the FMU reported {len(lines)} warning(s), {len(distinct)} distinct:",
          file=sys.stderr)
    for line in distinct[:shown]:
        print(f"  {line}", file=sys.stderr)
    if len(distinct) > shown:
        print(f"  … and {len(distinct) - shown} more (all in metadata.json)", file=sys.stderr)


def reduction_notice(parameters: dict, variables: dict):
    if int(start_value(variables, parameters, "scene") or 1) == 2:
        print("note: the first run of a chassis configuration reduces the body (seconds to "
              "minutes); later runs read it from the cache", file=sys.stderr)


def write_metadata(out: pathlib.Path, args, variables: dict, cases: list[tuple[str, dict]],
                   extra: dict | None = None, fmu_warnings: list[str] | None = None):
    """metadata.json: which FMU (checksum), which non-default parameters per case, the command,
    the package versions and the date: what a result in a report must be traceable to."""

    # Deferred: fmpy imports numpy, which the command line does not need to start.
    from fmpy import read_model_description

    fmu = args.fmu
    digest = file_sha256(fmu)
    md = read_model_description(fmu)

    def non_default(parameters: dict) -> dict:
        changed = {}
        for name, value in parameters.items():
            v = variables.get(name)
            start = None if v is None else v.start
            if v is not None and v.type == "Boolean" and isinstance(start, str):
                start = start.lower() == "true"
            try:
                same = start is not None and type(value)(start) == value
            except (TypeError, ValueError):
                same = False
            if not same:
                changed[name] = value
        return changed

    def version(package: str) -> str | None:
        try:
            return importlib_metadata.version(package)
        except importlib_metadata.PackageNotFoundError:
            return None

    record = {
        "fmu": {"path": str(pathlib.Path(fmu).resolve()), "sha256": digest, "guid": md.guid,
                "generationDateAndTime": md.generationDateAndTime, "modelName": md.modelName,
                "fileModified": datetime.datetime.fromtimestamp(
                    pathlib.Path(fmu).stat().st_mtime, datetime.timezone.utc
                ).isoformat(timespec="seconds")},
        # Per case: the parameters that differ from the model description's start values, and
        # every start value emc set (its defaults, the common --set, the case's own).
        "cases": {label: non_default(params) for label, params in cases},
        "settings": {label: dict(params) for label, params in cases},
        "command": args.command_line,
        "versions": {"python": platform.python_version(),
                     **{p: version(p) for p in ("emc", "fmpy", "numpy", "pandas", "dask",
                                                "distributed", "matplotlib")}},
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "fmu_warnings": list(dict.fromkeys(fmu_warnings or [])),
        **(extra or {}),
        # What the output-folder policy compares a later run in this folder with, and removes
        # with --overwrite.
        "run": {"command": getattr(args, "command", None), "settings": run_settings(args)},
        "written": written_files(out, args),
    }
    (out / "metadata.json").write_text(json.dumps(record, indent=2, default=str) + "\n")
