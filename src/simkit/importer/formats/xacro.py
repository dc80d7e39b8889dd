"""xacro: a `.xacro` (`.urdf.xacro`) file, expanded, then read and kept as a URDF (issue 24).

The format's row (formats.FORMATS): `sniff` by the file's name, `read` expands it and reads
the expansion as formats/urdf does (kept as read, then repaired), `keep` and `EDITS` are the
URDF's (the kept source is the expansion, NAME.source.urdf).

The expansion uses the xacro package, safely unless the user trusts the file.

xacro's module functions are swapped for the duration of one expansion (its state is
module-global, so expansions are serialised by a lock):

- `safe_eval`: the AST-walking evaluator of importer/read/safe_eval.py over a symbol table of
  math, a few builtins and xacro's own helpers (no `python.vars`, no `python.type`);
- `eval_extension`: `$(arg)` from --xacro-arg or the xacro's default, `$(find PKG)` through
  the PackageMap, `$(env X)` refused and `$(optenv X D)` giving D unless --allow-env X,
  `$(eval ...)` by the safe evaluator, `$(cwd)` refused;
- `parse` (includes) and `load_yaml`: only files under the robot's package folders or an
  --allow-read folder, and each file read with the lenient XML declaration rules;
- `handle_macro_call`: bounded macro depth, calls and expanded nodes; the output is bounded.

`--trust-xacro` runs xacro as it is (its Python evaluator, the environment, any file), with
only `$(find)` answered by the PackageMap. Every refusal is one line naming the file and the
line (the first line of that file holding the expression or macro).
"""

from __future__ import annotations

import io
import os
import threading
from contextlib import contextmanager
from pathlib import Path
from xml.sax.saxutils import escape

from simkit.errors import SpecError
from simkit.importer.formats import urdf
from simkit.importer.formats.urdf.parse import document
from simkit.importer.read import lenient
from simkit.importer.read.lenient import Position
from simkit.importer.read.options import ReadOptions
from simkit.importer.read.packages import PackageMap
from simkit.importer.read.safe_eval import BUILTINS, MATH, MAX_WORK, Evaluator, Refused
from simkit.importer.read.source import Source

#: nested macro calls
MAX_MACRO_DEPTH = 100
#: macro calls in one expansion
MAX_MACRO_CALLS = 20_000
#: XML nodes expanded by macro calls in one expansion
MAX_MACRO_NODES = 2_000_000
#: bytes of the expanded URDF
MAX_OUTPUT = 64 * 1024 * 1024

_LOCK = threading.Lock()


class Limit(Refused):
    """A bound on the expansion's work was reached (the message names it)."""


def expand(path: Path, packages: PackageMap, options: ReadOptions, source) -> bytes:
    """The expanded URDF bytes of xacro file `path`; SpecError (one line) on refusal."""
    import xacro

    run = _Run(xacro, path.resolve(), packages, options, source)
    with _LOCK, run.hooked():
        try:
            doc = xacro.process_file(str(path.resolve()), mappings=dict(options.xacro_args))
            text = doc.toxml(encoding="utf-8")
        except SpecError:
            raise
        except Refused as exc:
            raise run.error(exc) from None
        except Exception as exc:  # xacro raises many types; report one line
            inner = exc
            while getattr(inner, "exc", None) is not None:
                inner = inner.exc
            if isinstance(inner, Refused):
                raise run.error(inner) from None
            if isinstance(inner, SpecError):
                raise inner from None
            message = " ".join(str(exc).split()) or type(exc).__name__
            line = getattr(exc, "lineno", None)  # expat's, for malformed XML
            raise SpecError(
                run.current(), line, "xacro", f"xacro expansion failed: {message}"
            ) from None
    if len(text) > MAX_OUTPUT and not options.trust_xacro:
        raise SpecError(
            str(path),
            None,
            "xacro",
            f"expanded URDF of {len(text)} bytes is over the limit of {MAX_OUTPUT}",
        )
    return text


class _Run:
    """One expansion: the hooks and the state they share."""

    def __init__(self, xacro, path: Path, packages: PackageMap, options: ReadOptions, source):
        self.xacro, self.path, self.packages, self.options = xacro, path, packages, options
        self.source = source
        self.calls = self.nodes = 0
        self.where: tuple[str, str] = (str(path), "")
        self.symbols = self._symbols()
        self.callables = {id(v) for v in self._callables()}
        self.namespaces = (xacro.Table, xacro.YamlDictWrapper)
        self.budget = [MAX_WORK]

    # -- errors ------------------------------------------------------------------------
    def current(self) -> str:
        stack = self.xacro.filestack or [str(self.path)]
        return str(stack[-1] or self.path)

    def error(self, exc: Refused) -> SpecError:
        """One line naming the file and the first line of it holding the text refused."""
        file, text = self.where
        line = None
        try:
            lines = Path(file).read_text(encoding="utf-8", errors="replace").splitlines()
            forms = [f for f in (text, escape(text), escape(text, {'"': "&quot;"})) if f]
            line = next((i + 1 for i, t in enumerate(lines) if any(f in t for f in forms)), None)
        except OSError:
            pass
        field = "xacro" if isinstance(exc, Limit) else "xacro expression"
        return SpecError(file, line, field, f"{exc} (--trust-xacro runs a trusted file as is)")

    # -- the safe symbol table ---------------------------------------------------------
    def _symbols(self) -> dict:
        xacro = self.xacro
        python, math_ns, xacro_ns = xacro.NameSpace(), xacro.NameSpace(), xacro.NameSpace()
        python.update(BUILTINS)
        math_ns.update(MATH)
        xacro_ns.update(
            load_yaml=self._load_yaml,
            abs_filename=xacro.abs_filename_spec,
            dotify=xacro.YamlDictWrapper,
            arg=lambda name: xacro.substitution_args_context["arg"][name],
            tokenize=xacro.tokenize,
            fatal=self._fatal,
            message=self._quiet,
            warning=self._quiet,
            error=self._quiet,
            print_location=self._quiet,
        )
        out = dict(BUILTINS)
        out.update(MATH)
        out.update(python=python, math=math_ns, xacro=xacro_ns, load_yaml=self._load_yaml)
        return out

    def _callables(self) -> list:
        found = [v for v in self.symbols.values() if callable(v)]
        for space in ("python", "math", "xacro"):
            found += [v for v in self.symbols[space].values() if callable(v)]
        return found

    @staticmethod
    def _quiet(*args, **kwargs) -> str:
        return ""

    def _fatal(self, *args) -> None:
        raise self.xacro.XacroException("xacro.fatal: " + " ".join(map(str, args)))

    # -- hooks ---------------------------------------------------------------------------
    @contextmanager
    def hooked(self):
        xacro = self.xacro
        names = ("parse", "eval_extension")
        if not self.options.trust_xacro:
            names += ("safe_eval", "_global_symbols", "handle_macro_call")
        saved = {name: getattr(xacro, name) for name in names}
        self.original = saved
        replacement = {
            "parse": self._parse,
            "eval_extension": self._extension,
            "safe_eval": self._eval,
            "_global_symbols": self.symbols,
            "handle_macro_call": self._macro,
        }
        try:
            for name in names:
                setattr(xacro, name, replacement[name])
            yield
        finally:
            for name, value in saved.items():
                setattr(xacro, name, value)

    def _eval(self, expr, symbols, locals=None):
        text = str(expr)
        self.where = (self.current(), text.strip())
        return Evaluator(symbols, self.callables, self.namespaces, self.budget).run(text)

    def _readable(self, path: Path, what: str) -> None:
        if self.options.trust_xacro or self.packages.allowed(path):
            return
        self.where = (self.current(), path.name)
        raise Refused(
            f"{what} {path} refused: outside the robot's package folders (pass --allow-read DIR)"
        )

    def _parse(self, inp, filename=None):
        if inp is not None:
            return self.original["parse"](inp, filename)
        name = str(filename)
        if "package://" in name:
            uri = name[name.index("package://") :]
            where = (self.current(), None, "xacro:include")
            path = self.packages.resolve(uri, where)
        else:
            path = Path(os.path.join(self.xacro.root_dir, name))
        self._readable(path, "include")
        try:
            data = path.read_bytes()
        except OSError as exc:
            self.xacro.filestack.pop()
            raise self.xacro.XacroException(f"{exc.strerror}: {path}", exc=exc) from None
        data, notes = lenient.fix_declaration(data)
        for line, message in notes:
            self.source.lenient(Position("xml", line), f"{path.name}: {message}")
        return self.original["parse"](io.BytesIO(data), filename)

    def _load_yaml(self, filename):
        path = Path(self.xacro.abs_filename_spec(str(filename)))
        self._readable(path, "load_yaml")
        return self.xacro.load_yaml(str(path))

    def _extension(self, text: str):
        inner = text[2:-1].strip()
        command, _, rest = inner.partition(" ")
        args = rest.split()
        self.where = (self.current(), text)
        if command == "eval" and self.options.trust_xacro:
            return self.original["eval_extension"](text)
        if command == "eval":
            names = {**self.symbols, **self.xacro.substitution_args_context.get("arg", {})}
            return str(Evaluator(names, self.callables, self.namespaces, self.budget).run(rest))
        if command == "arg" and len(args) == 1:
            try:
                return self.xacro.substitution_args_context["arg"][args[0]]
            except KeyError:
                raise self.xacro.XacroException(
                    f"Undefined substitution argument {args[0]} (pass --xacro-arg {args[0]}:=VALUE)"
                ) from None
        if command == "find" and len(args) == 1:
            found = self.packages.find(args[0])
            return str(found) if found is not None else f"package://{args[0]}"
        if command in ("env", "optenv") and args:
            allowed = self.options.trust_xacro or args[0] in self.options.allow_env
            if allowed and args[0] in os.environ:
                return os.environ[args[0]]
            if command == "optenv":
                return " ".join(args[1:])
            if not allowed:
                raise Refused(f"$(env {args[0]}) refused: pass --allow-env {args[0]} to read it")
            raise self.xacro.XacroException(f"environment variable {args[0]} is not set")
        if command == "dirname" and not args:
            return os.path.dirname(os.path.abspath(self.current()))
        if command == "cwd" and self.options.trust_xacro:
            return os.getcwd()
        if command == "cwd":
            raise Refused("$(cwd) refused: it reads the environment (--trust-xacro allows it)")
        raise self.xacro.XacroException(f"unknown or malformed substitution {text}")

    def _macro(self, node, macros, symbols):
        if not node.tagName.startswith("xacro:"):
            return False
        self.where = (self.current(), f"<{node.tagName}")
        if len(self.xacro.macrostack) >= MAX_MACRO_DEPTH:
            raise Limit(
                f"macro depth over the limit of {MAX_MACRO_DEPTH} (a macro calling itself?)"
            )
        self.calls += 1
        if self.calls > MAX_MACRO_CALLS:
            raise Limit(f"over the limit of {MAX_MACRO_CALLS} macro calls in one expansion")
        self.nodes += len(node.getElementsByTagName("*")) + 1
        name = node.tagName[len("xacro:") :]
        if name != "call":
            try:
                body = self.xacro.resolve_macro(name, macros, symbols)[2].body
                self.nodes += len(body.getElementsByTagName("*"))
            except KeyError:
                pass  # xacro reports the unknown macro
        if self.nodes > MAX_MACRO_NODES:
            raise Limit(f"macros expanded over the limit of {MAX_MACRO_NODES} XML elements")
        return self.original["handle_macro_call"](node, macros, symbols)


def sniff(path: Path, head: bytes) -> bool:
    """A xacro by its name: `.xacro` (`.urdf.xacro` included)."""
    return path.suffix == ".xacro" or path.name.endswith(".urdf.xacro")


def title(head: bytes) -> str | None:
    """The file's name names the robot (None)."""
    return None


def read(shell: Source, options: ReadOptions) -> Source:
    """`shell` (path and PackageMap, no root yet) with its xacro expanded (`expand`) and the
    expansion parsed, kept and repaired as a URDF (formats/urdf)."""
    return urdf.repaired(document(shell, expand(shell.path, shell.packages, options, shell)))


NOUN = urdf.NOUN
keep = urdf.keep
EDITS = urdf.EDITS
AFTER = urdf.AFTER
