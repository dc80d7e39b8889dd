"""Import every robot file of a corpus with `simkit import`'s default flags, no build.

    python scripts/import_snapshot.py CORPUS_DIR OUT_DIR [--mjcf | --sdf] [--movable-only]
        [--only GLOB ...] [--exclude GLOB ...] [--timeout S]

The files are chosen as scripts/import_corpus.py chooses them (same flags). Each import runs
`simkit import FILE --out OUT_DIR/REL` in a forked child (the CLI itself, so the flags are
its defaults), REL being the file's path below CORPUS_DIR; OUT_DIR/REL/_cli.txt holds the
exit status and what the command printed, the output folder's absolute path replaced by
`OUT`. Two snapshots, say before and after an importer change, are then compared with
`diff -r`: a byte-identical importer gives no difference. No robot is named here."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from import_corpus import urdfs


def _child(path: Path, out: Path, log: Path) -> None:
    """In the forked child: run the CLI, stdout and stderr into `log`, never return."""
    fd = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
    os.dup2(fd, 1)
    os.dup2(fd, 2)
    code = 1
    try:
        from simkit.cli import main

        main(["import", str(path), "--out", str(out)], standalone_mode=True)
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException as exc:  # a traceback is a finding: keep its last line
        print(f"Traceback: {type(exc).__name__}: {exc}")
    finally:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)


def one(path: Path, out: Path, timeout: float) -> str:
    """Import `path` into `out`; the status line (exit code or timeout)."""
    out.mkdir(parents=True, exist_ok=True)
    log = out.parent / f".{out.name}.log"
    pid = os.fork()
    if pid == 0:
        _child(path, out, log)
    start = time.monotonic()
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            code = os.waitstatus_to_exitcode(status)
            break
        if time.monotonic() - start > timeout:
            os.kill(pid, 9)
            os.waitpid(pid, 0)
            code = "timeout"
            break
        time.sleep(0.05)
    text = log.read_text(errors="replace").replace(str(out), "OUT")
    log.unlink()
    (out / "_cli.txt").write_text(f"exit {code}\n{text}")
    return f"exit {code}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("corpus", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--exclude", action="append", default=[])
    parser.add_argument("--only", action="append", default=[])
    parser.add_argument("--movable-only", action="store_true")
    parser.add_argument("--mjcf", action="store_true")
    parser.add_argument("--sdf", action="store_true")
    parser.add_argument("--timeout", type=float, default=900.0, help="s per import")
    args = parser.parse_args()
    root = args.corpus.resolve()
    found = urdfs(root, args.exclude, args.movable_only, args.only, args.mjcf, args.sdf)
    import simkit.cli  # noqa: F401  (imported once, before the forks)

    for i, path in enumerate(found, 1):
        rel = path.relative_to(root).as_posix()
        start = time.monotonic()
        status = one(path, args.out.resolve() / rel, args.timeout)
        print(f"[{i}/{len(found)}] {rel}: {status} {time.monotonic() - start:.1f} s", flush=True)


if __name__ == "__main__":
    main()
