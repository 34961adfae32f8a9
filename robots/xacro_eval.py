"""Evaluate a xacro ``${...}`` expression by a whitelist, never by Python's ``eval``.

The expression is parsed with :mod:`ast` and every node is checked against a fixed list
before anything runs; evaluation then walks the tree itself. Allowed:

- literals: numbers, strings, ``True``/``False``/``None``, lists, tuples and dicts of them;
- arithmetic ``+ - * / // % **`` and unary ``+ - not``; comparisons (``== != < <= > >= in
  not in is is not``); ``and``/``or``; ``a if c else b``;
- names of xacro properties and arguments (looked up in the symbol table xacro hands over,
  so a property shadows a function of the same name, as in xacro), ``ns.name`` in a
  namespace of ``<xacro:include ns=...>`` and ``cfg.key`` in a dict read by ``load_yaml``;
- subscripts and slices of lists, tuples, dicts and strings;
- calls of the functions in :data:`FUNCTIONS` (and those the caller adds, such as
  ``xacro.arg``), by their plain or ``math.`` name; the constants ``pi e tau inf nan``.

Everything else is refused by name with :class:`ExpressionRefused`: attribute access to
anything else (``x.__class__``, ``'{}'.format``, ``python.vars``, ``xacro.abs_filename``),
calls of anything else (``getattr``, ``type``, ``map``), ``lambda``, comprehensions,
generators, f-strings, ``:=``, ``*args``, sets, bitwise operators and ``%`` on strings.
Sizes are bounded before they are computed (:class:`ExpressionTooLarge`): integers up to
:data:`MAX_INT_BITS` bits, strings/lists/dicts up to :data:`MAX_LENGTH` items, expression
text up to :data:`MAX_EXPRESSION_CHARS` characters and :data:`MAX_DEPTH` levels, so
``${9**9**9}`` and ``${'a' * 10**9}`` fail at once.

This module imports only the standard library: the xacro expansion child loads it by path.
"""

from __future__ import annotations

import ast
import math
import operator
from functools import lru_cache
from typing import Any, Callable, Mapping

__all__ = [
    "ExpressionError",
    "ExpressionRefused",
    "ExpressionTooLarge",
    "FUNCTIONS",
    "CONSTANTS",
    "MAX_INT_BITS",
    "MAX_LENGTH",
    "MAX_EXPRESSION_CHARS",
    "MAX_DEPTH",
    "check_expression",
    "evaluate",
]

#: Largest integer an expression may produce [bits] (2**4096 ≈ 1e1233; floats end at 1e308).
MAX_INT_BITS = 4096
#: Longest string, list, tuple or dict an expression may produce [items].
MAX_LENGTH = 2**20
#: Longest expression text [characters].
MAX_EXPRESSION_CHARS = 10_000
#: Deepest nesting of an expression's syntax tree [levels].
MAX_DEPTH = 100


class ExpressionError(ValueError):
    """An expression pinarms does not evaluate; ``expression`` is its text, ``construct`` what was refused."""

    def __init__(self, expression: str, construct: str, message: str) -> None:
        super().__init__(f"expression '{expression}': {message}")
        self.expression = expression
        self.construct = construct


class ExpressionRefused(ExpressionError):
    """The expression uses a construct outside the whitelist (named in the message)."""


class ExpressionTooLarge(ExpressionError):
    """The expression would build a number, string or list beyond the size bounds."""


def _round(number: Any, ndigits: Any = None) -> Any:
    if ndigits is not None and (not isinstance(ndigits, int) or abs(ndigits) > 400):
        raise ValueError(f"round(): ndigits must be an integer within ±400, got {ndigits!r}")
    return round(number) if ndigits is None else round(number, ndigits)


_MATH_FUNCTIONS = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh",
                   "acosh", "atanh", "sqrt", "exp", "log", "log10", "log2", "hypot", "radians", "degrees",
                   "floor", "ceil", "fabs", "copysign", "fmod", "trunc", "isclose", "isfinite", "isinf",
                   "isnan", "pow")
#: The functions an expression may call: ``name -> function`` (``math.name`` too for math's).
FUNCTIONS: Mapping[str, Callable[..., Any]] = {
    **{name: getattr(math, name) for name in _MATH_FUNCTIONS},
    **{f"math.{name}": getattr(math, name) for name in _MATH_FUNCTIONS},
    "abs": abs, "min": min, "max": max, "round": _round, "int": int, "float": float, "bool": bool,
    "str": str, "len": len,
}
#: The constants an expression may name when no property of that name exists.
CONSTANTS: Mapping[str, float] = {
    **{name: getattr(math, name) for name in ("pi", "e", "tau", "inf", "nan")},
    **{f"math.{name}": getattr(math, name) for name in ("pi", "e", "tau", "inf", "nan")},
}

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod, ast.Pow: operator.pow}
_UNARY = {ast.UAdd: operator.pos, ast.USub: operator.neg, ast.Not: operator.not_}
_COMPARE = {ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
            ast.Gt: operator.gt, ast.GtE: operator.ge, ast.In: lambda a, b: a in b,
            ast.NotIn: lambda a, b: a not in b, ast.Is: operator.is_, ast.IsNot: operator.is_not}
_PLAIN = (ast.Expression, ast.Constant, ast.Name, ast.Load, ast.BinOp, ast.UnaryOp, ast.BoolOp, ast.And,
          ast.Or, ast.Compare, ast.IfExp, ast.Call, ast.keyword, ast.Attribute, ast.Subscript, ast.Slice,
          ast.List, ast.Tuple, ast.Dict, *_BINARY, *_UNARY, *_COMPARE)
_NAMED = {
    ast.Lambda: "lambda", ast.ListComp: "a list comprehension", ast.SetComp: "a set comprehension",
    ast.DictComp: "a dict comprehension", ast.GeneratorExp: "a generator expression",
    ast.JoinedStr: "an f-string", ast.FormattedValue: "an f-string", ast.NamedExpr: "the assignment ':='",
    ast.Starred: "a starred '*' argument", ast.Set: "a set", ast.Await: "await", ast.Yield: "yield",
    ast.YieldFrom: "yield", ast.BitAnd: "the operator '&'", ast.BitOr: "the operator '|'",
    ast.BitXor: "the operator '^'", ast.LShift: "the operator '<<'", ast.RShift: "the operator '>>'",
    ast.MatMult: "the operator '@'", ast.Invert: "the operator '~'", ast.Store: "an assignment",
}
_SCALARS = (bool, int, float, str, type(None))
_DATA = (*_SCALARS, complex)  # complex: a result only ((-8) ** 0.5), as Python gives it


def _refuse(expr: str, construct: str, what: str) -> ExpressionRefused:
    return ExpressionRefused(
        expr, construct, f"{what} is not allowed (pinarms evaluates ${{...}} with numbers, strings, "
        "arithmetic, comparisons, and/or/not, 'a if c else b', property names and a fixed set of math functions)"
    )


def _refusal(text: str, node: ast.AST) -> ExpressionRefused | None:
    kind = type(node)
    if kind in _NAMED:
        return _refuse(text, kind.__name__, f"{_NAMED[kind]} ({kind.__name__})")
    if kind not in _PLAIN:
        return _refuse(text, kind.__name__, f"the construct {kind.__name__}")
    if kind is ast.Constant and not isinstance(node.value, _SCALARS):
        return _refuse(text, "Constant", f"the literal {node.value!r} ({type(node.value).__name__})")
    name = node.id if kind is ast.Name else node.attr if kind is ast.Attribute else None
    if name is not None and name.startswith("__"):
        return _refuse(text, "dunder", f"the name '{name}' (names starting with '__')")
    if kind is ast.Dict and any(key is None for key in node.keys):
        return _refuse(text, "DictUnpack", "dict unpacking '**'")
    if kind is ast.keyword and node.arg is None:
        return _refuse(text, "KeywordUnpack", "keyword unpacking '**'")
    return None


@lru_cache(maxsize=4096)
def check_expression(expr: str) -> ast.Expression:
    """Parse ``expr`` and check every node against the whitelist; the checked tree.

    Raises:
        ExpressionRefused: a construct outside the whitelist (named in the message).
        ExpressionTooLarge: the text or its nesting is beyond the bounds.
        SyntaxError: not a Python expression.
    """
    text = expr.strip()
    if len(text) > MAX_EXPRESSION_CHARS:
        raise ExpressionTooLarge(text[:60] + "...", "length",
                                 f"{len(text)} characters, more than the {MAX_EXPRESSION_CHARS} allowed")
    try:
        tree = ast.parse(text, mode="eval")
    except (MemoryError, RecursionError):  # CPython's parser gives up on ~1000 nested unary operators
        raise ExpressionTooLarge(text[:60] + "...", "depth", f"nested deeper than {MAX_DEPTH} levels") from None
    refusals: list[tuple[tuple[bool, int, int, int], ExpressionRefused]] = []
    stack: list[tuple[ast.AST, int]] = [(tree, 0)]
    while stack:
        node, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ExpressionTooLarge(text, "depth", f"nested deeper than {MAX_DEPTH} levels")
        refusal = _refusal(text, node)
        if refusal is not None:  # reported in reading order: the first refused construct of the text
            end = getattr(node, "end_col_offset", None)  # parts without a place (a lambda's arguments) come last
            refusals.append(((end is None, getattr(node, "end_lineno", 0), end or 0, depth), refusal))
        stack.extend((child, depth + 1) for child in ast.iter_child_nodes(node))
    if refusals:
        raise min(refusals, key=lambda item: item[0])[1]
    return tree


class _Function:
    __slots__ = ("name", "fn")

    def __init__(self, name: str, fn: Callable[..., Any]) -> None:
        self.name, self.fn = name, fn


class _Namespace:
    __slots__ = ("name", "table")

    def __init__(self, name: str, table: Any) -> None:
        self.name, self.table = name, table


_MISSING = object()


class _Evaluator:
    def __init__(self, text: str, symbols: Mapping[str, Any], functions: Mapping[str, Callable[..., Any]],
                 namespaces: tuple[type, ...], attr_dicts: tuple[type, ...]) -> None:
        self.text, self.symbols, self.functions = text, symbols, functions
        self.namespaces, self.attr_dicts = namespaces, attr_dicts

    def refuse(self, construct: str, what: str) -> ExpressionRefused:
        return _refuse(self.text, construct, what)

    def too_large(self, what: str) -> ExpressionTooLarge:
        return ExpressionTooLarge(self.text, "size", f"{what} (bounds: integers of {MAX_INT_BITS} bits, "
                                  f"strings and lists of {MAX_LENGTH} items)")

    def classify(self, qualified: str, value: Any) -> Any:
        """A looked-up value as the evaluator holds it: data, a namespace or an allowed function."""
        if value is not _MISSING and self.is_data(value):
            return value
        if qualified in self.functions:
            return _Function(qualified, self.functions[qualified])
        if value is _MISSING and qualified in CONSTANTS:
            return CONSTANTS[qualified]
        if value is not _MISSING and isinstance(value, self.namespaces):
            return _Namespace(qualified, value)
        if value is _MISSING and any(q.startswith(qualified + ".") for q in (*self.functions, *CONSTANTS)):
            return _Namespace(qualified, None)
        if value is _MISSING:
            raise NameError(f"name '{qualified}' is not defined")
        raise self.refuse("name", f"'{qualified}' (a {type(value).__name__}, not one of the allowed functions)")

    def is_data(self, value: Any) -> bool:
        if isinstance(value, _DATA):
            return True
        return isinstance(value, (list, tuple, dict)) and not isinstance(value, self.namespaces)

    def data(self, node: ast.AST) -> Any:
        value = self.eval(node)
        if isinstance(value, _Function):
            raise self.refuse("function", f"using the function '{value.name}' as a value")
        if isinstance(value, _Namespace):
            raise self.refuse("namespace", f"using the namespace '{value.name}' as a value")
        return value

    def bounded(self, value: Any) -> Any:
        if isinstance(value, int) and value.bit_length() > MAX_INT_BITS:
            raise self.too_large(f"an integer of {value.bit_length()} bits")
        if isinstance(value, (str, list, tuple, dict)) and len(value) > MAX_LENGTH:
            raise self.too_large(f"a {type(value).__name__} of {len(value)} items")
        return value

    def eval(self, node: ast.AST) -> Any:
        method = getattr(self, "eval_" + type(node).__name__)
        return method(node)

    def eval_Expression(self, node: ast.Expression) -> Any:
        return self.data(node.body)

    def eval_Constant(self, node: ast.Constant) -> Any:
        return node.value

    def eval_Name(self, node: ast.Name) -> Any:
        try:
            value = self.symbols[node.id]
        except KeyError:
            value = _MISSING
        return self.classify(node.id, value)

    def eval_Attribute(self, node: ast.Attribute) -> Any:
        base = self.eval(node.value)
        if isinstance(base, _Namespace):
            qualified = f"{base.name}.{node.attr}"
            try:
                value = base.table[node.attr] if base.table is not None else _MISSING
            except KeyError:
                value = _MISSING
            return self.classify(qualified, value)
        if self.attr_dicts and isinstance(base, self.attr_dicts):
            return base[node.attr]  # a yaml dict's key, by xacro's own dotted access
        kind = "function" if isinstance(base, _Function) else type(base).__name__
        raise self.refuse("attribute", f"the attribute '.{node.attr}' of a {kind} value")

    def eval_Subscript(self, node: ast.Subscript) -> Any:
        base = self.data(node.value)
        if not isinstance(base, (list, tuple, dict, str)):
            raise self.refuse("subscript", f"a subscript of a {type(base).__name__} value")
        return self.bounded(base[self.data(node.slice)])

    def eval_Slice(self, node: ast.Slice) -> slice:
        parts = [None if p is None else self.data(p) for p in (node.lower, node.upper, node.step)]
        return slice(*parts)

    def eval_List(self, node: ast.List) -> list:
        return self.bounded([self.data(e) for e in node.elts])

    def eval_Tuple(self, node: ast.Tuple) -> tuple:
        return self.bounded(tuple(self.data(e) for e in node.elts))

    def eval_Dict(self, node: ast.Dict) -> dict:
        return self.bounded({self.data(k): self.data(v) for k, v in zip(node.keys, node.values)})

    def eval_UnaryOp(self, node: ast.UnaryOp) -> Any:
        return _UNARY[type(node.op)](self.data(node.operand))

    def eval_BinOp(self, node: ast.BinOp) -> Any:
        left, right = self.data(node.left), self.data(node.right)
        op = type(node.op)
        if op is ast.Pow:
            self.check_power(left, right)
        elif op is ast.Mult:
            self.check_product(left, right)
        elif op is ast.Mod and isinstance(left, str):
            raise self.refuse("format", "string formatting with '%'")
        elif op is ast.Add and isinstance(left, (str, list, tuple)) and isinstance(right, type(left)):
            if len(left) + len(right) > MAX_LENGTH:
                raise self.too_large(f"a {type(left).__name__} of {len(left) + len(right)} items")
        return self.bounded(_BINARY[op](left, right))

    def check_power(self, base: Any, exponent: Any) -> None:
        if isinstance(base, int) and isinstance(exponent, int) and exponent > 0 and abs(base) > 1:
            bits = exponent * math.log2(abs(base))
            if bits > MAX_INT_BITS:
                raise self.too_large(f"{base}**{exponent} has about {bits:.3g} bits")

    def check_product(self, left: Any, right: Any) -> None:
        for seq, count in ((left, right), (right, left)):
            if isinstance(seq, (str, list, tuple)) and isinstance(count, int) and len(seq) * count > MAX_LENGTH:
                raise self.too_large(f"a {type(seq).__name__} of {len(seq)} items repeated {count} times")
        if isinstance(left, int) and isinstance(right, int) and left.bit_length() + right.bit_length() > MAX_INT_BITS + 1:
            raise self.too_large(f"a product of {left.bit_length() + right.bit_length()} bits")

    def eval_BoolOp(self, node: ast.BoolOp) -> Any:
        value = None
        for operand in node.values:
            value = self.data(operand)
            if (not value) if isinstance(node.op, ast.And) else value:
                return value
        return value

    def eval_Compare(self, node: ast.Compare) -> Any:
        left = self.data(node.left)
        for op, comparator in zip(node.ops, node.comparators):
            right = self.data(comparator)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def eval_IfExp(self, node: ast.IfExp) -> Any:
        return self.data(node.body) if self.data(node.test) else self.data(node.orelse)

    def eval_Call(self, node: ast.Call) -> Any:
        try:
            fn = self.eval(node.func)
        except NameError:  # getattr, eval, open, type, ...: no such function here
            raise self.refuse("call", f"calling '{ast.unparse(node.func)}', which is not one of the allowed "
                              "functions") from None
        if not isinstance(fn, _Function):
            what = f"the namespace '{fn.name}'" if isinstance(fn, _Namespace) else f"a {type(fn).__name__} value"
            raise self.refuse("call", f"calling {what}")
        args = [self.data(a) for a in node.args]
        kwargs = {k.arg: self.data(k.value) for k in node.keywords}
        return self.bounded(fn.fn(*args, **kwargs))


def evaluate(
    expr: str,
    symbols: Mapping[str, object],
    *,
    functions: Mapping[str, Callable[..., object]] | None = None,
    namespaces: tuple[type, ...] = (),
    attr_dicts: tuple[type, ...] = (),
) -> Any:
    """The value of the ``${...}`` expression ``expr`` (without ``${}``), by the whitelist.

    Args:
        symbols: property and argument values by name (``symbols[name]`` raises
            ``KeyError`` for an unknown name); values that are not data (functions,
            modules) are usable only when their name is in ``functions``.
        functions: the callable names (default :data:`FUNCTIONS`).
        namespaces: types of name-space tables (``ns.name`` looks ``name`` up in them).
        attr_dicts: dict types whose keys may be read as ``d.key``.

    Raises:
        ExpressionRefused, ExpressionTooLarge: see the module doc.
        NameError, ZeroDivisionError, ValueError, TypeError, OverflowError, ...: as
            Python's ``eval`` of the same (allowed) expression would.
    """
    tree = check_expression(expr)
    evaluator = _Evaluator(expr.strip(), symbols, FUNCTIONS if functions is None else functions,
                           namespaces, attr_dicts)
    return evaluator.eval(tree)
