"""A restricted evaluator for xacro's `${...}` expressions (issue 24: a xacro runs code).

xacro evaluates expressions with Python's `eval`, which reaches the object graph
(`python.vars(python.type)['__subclasses__']`) and from there `os.system`. This evaluator
walks the expression's AST and allows only what robot descriptions use: literals,
arithmetic, comparisons, conditionals, subscripts, comprehensions, xacro's properties
(looked up in its symbol table) and a fixed set of functions (math, a few builtins, xacro's
own helpers). Every value it can reach is data or one of those functions, so there is no
path to Python objects: attributes are namespace lookups or whitelisted string, list and
dict methods, and a name or attribute beginning with `_` is refused.

Work is bounded: expression length, integer size (`${9**9**9}`), string and list length.
"""

from __future__ import annotations

import ast
import math
import operator
import re
from collections.abc import Callable, Mapping

#: characters of one expression
MAX_EXPRESSION = 10_000
#: bits of an integer result (2**4096 is far beyond any robot dimension)
MAX_INT_BITS = 4096
#: items of a string, list or range
MAX_ITEMS = 1_000_000
#: AST nodes of one expression
MAX_NODES = 2_000
#: items of all strings, lists and dicts made by the expressions of one expansion
MAX_WORK = 50_000_000


class Refused(Exception):
    """An expression the safe evaluator does not run; the message says why, in one line."""


#: builtins and names a xacro may not reach (named in the refusal as Python object access)
OBJECT_ACCESS = {
    "vars", "type", "getattr", "setattr", "delattr", "eval", "exec", "compile", "open",
    "globals", "locals", "dir", "object", "super", "input", "breakpoint", "help", "id",
    "memoryview", "classmethod", "staticmethod", "property", "isinstance", "issubclass",
    "hash", "callable", "format", "print", "exit", "quit", "os", "sys", "subprocess",
}  # fmt: skip
STR_METHODS = {
    "lower", "upper", "strip", "lstrip", "rstrip", "split", "rsplit", "replace",
    "startswith", "endswith", "join", "find", "rfind", "count", "title", "capitalize",
    "isdigit", "isalpha", "isalnum", "splitlines", "partition", "rpartition", "index",
}  # fmt: skip
LIST_METHODS = {"index", "count"}
DICT_METHODS = {"get", "keys", "values", "items"}

BINARY: dict[type, Callable] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
    ast.Div: operator.truediv, ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod,
    ast.Pow: operator.pow, ast.LShift: operator.lshift, ast.RShift: operator.rshift,
    ast.BitAnd: operator.and_, ast.BitOr: operator.or_, ast.BitXor: operator.xor,
}  # fmt: skip
UNARY: dict[type, Callable] = {
    ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_,
    ast.Invert: operator.invert,
}  # fmt: skip
COMPARE: dict[type, Callable] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
    ast.Gt: operator.gt, ast.GtE: operator.ge, ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b, ast.Is: operator.is_, ast.IsNot: operator.is_not,
}  # fmt: skip
FORMAT_WIDTH = re.compile(r"%[-#0 +]*(\*|\d+)?(?:\.(\*|\d+))?")


def _numeric_sum(items, start=0):
    """`sum` of numbers only (a list `start` would concatenate lists, quadratic in time)."""
    if not isinstance(start, int | float):
        raise Refused("sum() of non-numbers is not allowed in a safe xacro expression")
    return sum(items, start)


def _bounded_range(*args: int) -> range:
    out = range(*args)
    if len(out) > MAX_ITEMS:
        raise Refused(f"range of {len(out)} items is over the limit of {MAX_ITEMS}")
    return out


#: builtins an expression may call (xacro exposes these, globally and as `python.NAME`)
BUILTINS: dict[str, object] = {
    "list": list, "dict": dict, "tuple": tuple, "set": set, "frozenset": frozenset,
    "len": len, "str": str, "float": float, "int": int, "bool": bool, "min": min, "max": max,
    "round": round, "abs": abs, "all": all, "any": any, "sum": _numeric_sum, "sorted": sorted,
    "reversed": reversed, "enumerate": enumerate, "zip": zip, "map": map, "filter": filter,
    "divmod": divmod, "ord": ord, "chr": chr, "repr": repr, "range": _bounded_range,
    "True": True, "False": False, "None": None,
}  # fmt: skip
#: math functions whose work is not bounded by their argument's size are left out
MATH = {
    k: v
    for k, v in vars(math).items()
    if not k.startswith("_") and k not in ("factorial", "comb", "perm", "prod")
}


def check_size(value):
    """`value`, or Refused when it is a number or sequence over the limits."""
    if isinstance(value, bool):
        return value
    if isinstance(value, int) and value.bit_length() > MAX_INT_BITS:
        raise Refused(f"integer of {value.bit_length()} bits is over the limit of {MAX_INT_BITS}")
    if isinstance(value, str | bytes | list | tuple | dict | set) and len(value) > MAX_ITEMS:
        raise Refused(f"value of {len(value)} items is over the limit of {MAX_ITEMS}")
    return value


class Evaluator:
    """Evaluates one parsed expression against `names` (xacro's symbol table), `callables`
    (the identities of the functions it may call) and `namespaces` (types whose attributes
    are item lookups, e.g. xacro's NameSpace and its YAML dict wrapper)."""

    def __init__(
        self, names: Mapping, callables: set[int], namespaces: tuple[type, ...], budget: list[int]
    ):
        self.names = names
        self.callables = callables
        self.namespaces = namespaces
        self.scopes: list[dict] = []
        self.budget = budget  # [items left], shared by the expressions of one expansion

    def spend(self, value):
        """`value` after its size is checked and taken from the expansion's budget."""
        check_size(value)
        if isinstance(value, str | bytes | list | tuple | dict | set) and len(value) > 1:
            self.budget[0] -= len(value)
            if self.budget[0] < 0:
                raise Refused(f"expressions made over the limit of {MAX_WORK} items in all")
        return value

    def run(self, text: str):
        if len(text) > MAX_EXPRESSION:
            raise Refused(
                f"expression of {len(text)} characters is over the limit of {MAX_EXPRESSION}"
            )
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except SyntaxError as exc:
            raise Refused(f"invalid expression: {exc.msg}") from None
        if sum(1 for _ in ast.walk(tree)) > MAX_NODES:
            raise Refused(f"expression of over {MAX_NODES} syntax nodes")
        return self.eval(tree.body)

    def eval(self, node):
        method = getattr(self, f"do_{type(node).__name__}", None)
        if method is None:
            raise Refused(f"'{type(node).__name__}' is not allowed in a safe xacro expression")
        return self.spend(method(node))

    def do_Constant(self, node):
        return node.value

    def do_Name(self, node):
        name = node.id
        if name.startswith("_") or name in OBJECT_ACCESS:
            raise Refused(f"Python object access refused: '{name}'")
        for scope in reversed(self.scopes):
            if name in scope:
                return scope[name]
        try:
            return self.names[name]
        except KeyError:
            raise NameError(f"name '{name}' is not defined") from None

    def do_Attribute(self, node):
        owner = self.eval(node.value)
        attr = node.attr
        shown = f"{ast.unparse(node.value)}.{attr}"
        if attr.startswith("_") or attr in OBJECT_ACCESS:
            raise Refused(f"Python object access refused: '{shown}'")
        if isinstance(owner, self.namespaces):
            try:
                return owner[attr]
            except KeyError:
                raise NameError(f"name '{shown}' is not defined") from None
        methods = (
            STR_METHODS if isinstance(owner, str)
            else LIST_METHODS if isinstance(owner, list | tuple)
            else DICT_METHODS if isinstance(owner, dict)
            else set()
        )  # fmt: skip
        if attr not in methods:
            raise Refused(f"Python object access refused: '{shown}'")
        return getattr(owner, attr)

    def do_Subscript(self, node):
        owner, key = self.eval(node.value), self.eval(node.slice)
        if isinstance(key, str) and key.startswith("__"):
            raise Refused(f"Python object access refused: '[{key!r}]'")
        if not isinstance(owner, (str, list, tuple, dict, range, *self.namespaces)):
            raise Refused(f"Python object access refused: subscript of {type(owner).__name__}")
        return owner[key]

    def do_Slice(self, node):
        parts = (node.lower, node.upper, node.step)
        return slice(*(None if p is None else self.eval(p) for p in parts))

    def do_Tuple(self, node):
        return tuple(self.eval(e) for e in node.elts)

    def do_List(self, node):
        return [self.eval(e) for e in node.elts]

    def do_Set(self, node):
        return {self.eval(e) for e in node.elts}

    def do_Dict(self, node):
        if any(k is None for k in node.keys):
            raise Refused("'**' in a dict is not allowed in a safe xacro expression")
        return {self.eval(k): self.eval(v) for k, v in zip(node.keys, node.values, strict=True)}

    def do_UnaryOp(self, node):
        return UNARY[type(node.op)](self.eval(node.operand))

    def do_BinOp(self, node):
        left, right = self.eval(node.left), self.eval(node.right)
        _check_binary(node.op, left, right)
        return BINARY[type(node.op)](left, right)

    def do_BoolOp(self, node):
        value = None
        for item in node.values:
            value = self.eval(item)
            if isinstance(node.op, ast.And) and not value:
                return value
            if isinstance(node.op, ast.Or) and value:
                return value
        return value

    def do_Compare(self, node):
        left = self.eval(node.left)
        for op, item in zip(node.ops, node.comparators, strict=True):
            right = self.eval(item)
            if not COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def do_IfExp(self, node):
        return self.eval(node.body) if self.eval(node.test) else self.eval(node.orelse)

    def do_Call(self, node):
        func = self.eval(node.func)
        if any(isinstance(a, ast.Starred) for a in node.args) or any(
            k.arg is None for k in node.keywords
        ):
            raise Refused("'*' and '**' arguments are not allowed in a safe xacro expression")
        bound = getattr(func, "__self__", None)
        if id(func) not in self.callables and not isinstance(bound, str | list | tuple | dict):
            raise Refused(f"Python object access refused: call of '{ast.unparse(node.func)}'")
        args = [self.eval(a) for a in node.args]
        kwargs = {k.arg: self.eval(k.value) for k in node.keywords}
        if bound is not None and isinstance(bound, str):
            _check_string_call(bound, func.__name__, args)
        return func(*args, **kwargs)

    def _comprehension(self, node, make):
        if len(node.generators) != 1 or node.generators[0].is_async:
            raise Refused("only one 'for' per comprehension in a safe xacro expression")
        gen = node.generators[0]
        if not isinstance(gen.target, ast.Name | ast.Tuple):
            raise Refused("a comprehension's target must be a name or a tuple of names")
        items = self.eval(gen.iter)
        out = []
        self.scopes.append({})
        try:
            for count, item in enumerate(items):
                if count >= MAX_ITEMS:
                    raise Refused(f"comprehension over the limit of {MAX_ITEMS} items")
                self._bind(gen.target, item)
                if all(self.eval(test) for test in gen.ifs):
                    out.append(make())
        finally:
            self.scopes.pop()
        return out

    def _bind(self, target, item) -> None:
        if isinstance(target, ast.Name):
            if target.id.startswith("_"):
                raise Refused(f"Python object access refused: '{target.id}'")
            self.scopes[-1][target.id] = item
            return
        values = list(item)
        if len(values) != len(target.elts):
            raise ValueError("cannot unpack: wrong number of values")
        for sub, value in zip(target.elts, values, strict=True):
            self._bind(sub, value)

    def do_ListComp(self, node):
        return self._comprehension(node, lambda: self.eval(node.elt))

    do_GeneratorExp = do_ListComp

    def do_DictComp(self, node):
        return dict(self._comprehension(node, lambda: (self.eval(node.key), self.eval(node.value))))


def _check_binary(op, left, right) -> None:
    """Refuse an operation whose result would be too large before computing it."""
    numbers = (int, float)
    ints = isinstance(left, int) and isinstance(right, int)
    big = ints and right > 0 and abs(left) > 1 and right * math.log2(abs(left)) > MAX_INT_BITS
    if isinstance(op, ast.Pow) and big:
        raise Refused(f"exponent too large: **{right} is over the limit of {MAX_INT_BITS} bits")
    if isinstance(op, ast.LShift) and isinstance(right, int) and right > MAX_INT_BITS:
        raise Refused(f"shift of {right} bits is over the limit of {MAX_INT_BITS}")
    seq, count = (left, right) if not isinstance(left, numbers) else (right, left)
    repeated = isinstance(seq, str | list | tuple) and isinstance(count, int)
    if isinstance(op, ast.Mult) and repeated and len(seq) * count > MAX_ITEMS:
        raise Refused(f"repetition of {len(seq) * count} items is over the limit of {MAX_ITEMS}")
    if isinstance(op, ast.Mod) and isinstance(left, str):
        for width in FORMAT_WIDTH.findall(left):
            if "*" in width or any(w and int(w) > 1000 for w in width):
                raise Refused("a '%' format width over 1000 is not allowed")


def _check_string_call(text: str, name: str, args: list) -> None:
    """Refuse `join` and `replace` calls whose result would be over MAX_ITEMS, before
    making it."""
    size = 0
    if name == "join" and args:
        items = list(args[0]) if isinstance(args[0], list | tuple | str) else None
        if items is None:
            return
        size = sum(len(i) for i in items if isinstance(i, str)) + len(text) * len(items)
    elif name == "replace" and len(args) >= 2 and all(isinstance(a, str) for a in args[:2]):
        old, new = args[0], args[1]
        count = text.count(old) if old else len(text) + 1
        size = len(text) + count * max(0, len(new) - len(old))
    if size > MAX_ITEMS:
        raise Refused(f"{name}() of {size} characters is over the limit of {MAX_ITEMS}")
