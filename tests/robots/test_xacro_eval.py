"""The xacro expression whitelist: Python's result on what it allows, a named refusal otherwise."""

from __future__ import annotations

import math
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pinarms.robots.xacro_eval import (
    FUNCTIONS,
    MAX_DEPTH,
    MAX_EXPRESSION_CHARS,
    ExpressionRefused,
    ExpressionTooLarge,
    check_expression,
    evaluate,
)

SYMBOLS = {"a": 0.3, "b": -2.5, "n": 3, "k": 7, "flag": True, "s": "arm", "lst": [1, 2.5, -3], "cfg": {"x": 0.1}}
NAMES = {**SYMBOLS, **{name: fn for name, fn in FUNCTIONS.items() if "." not in name}, "pi": math.pi, "e": math.e}


def python(expr: str):
    return eval(expr, {"__builtins__": {}}, dict(NAMES))  # the reference: Python on the same names


def same(x, y) -> bool:
    if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
        return True
    return type(x) is type(y) and x == y


@pytest.mark.parametrize(
    "expr, expected",
    [
        ("a * 2 + n", 3.6),
        ("radians(30)", math.radians(30)),
        ("pi / 2", math.pi / 2),
        ("math.pi", math.pi),
        ("math.sin(pi / 2)", 1.0),
        ("-n ** 2", -9),
        ("n // 2, n % 2", (1, 1)),
        ("s * 2 + '_link'", "armarm_link"),
        ("lst[1]", 2.5),
        ("lst[0:2]", [1, 2.5]),
        ("cfg['x']", 0.1),
        ("a if flag else b", 0.3),
        ("not flag or n > 2 and n <= 3", True),
        ("0 < a < 1", True),
        ("'r' in s", True),
        ("min(lst) + max(1, 2) + abs(b) + len(s)", -3 + 2 + 2.5 + 3),
        ("round(2.567, 2)", 2.57),
        ("float('0.25') + int(7.9) + floor(1.5) + ceil(1.5)", 0.25 + 7 + 1 + 2),
        ("atan2(1, 1) == pi / 4", True),
        ("[1, 'a', None, True]", [1, "a", None, True]),
        ("{'k': (1, 2)}", {"k": (1, 2)}),
        ("2 ** -2", 0.25),
    ],
)
def test_allowed_expressions_give_pythons_value(expr, expected):
    assert evaluate(expr, SYMBOLS) == expected


def test_a_property_shadows_a_function_of_the_same_name_as_in_xacro():
    assert evaluate("floor + 1", {"floor": 0.02}) == pytest.approx(1.02, abs=1e-15)
    assert evaluate("pi", {"pi": 3}) == 3


def test_python_errors_stay_python_errors():
    with pytest.raises(ZeroDivisionError):
        evaluate("1 / (n - 3)", SYMBOLS)
    with pytest.raises(NameError, match="undefined_length"):
        evaluate("undefined_length * 2", SYMBOLS)
    with pytest.raises(ValueError, match="math domain"):
        evaluate("sqrt(-1)", SYMBOLS)
    with pytest.raises(SyntaxError):
        evaluate("1 +", SYMBOLS)


@pytest.mark.parametrize(
    "expr, needle",
    [
        ("().__class__.__bases__[0].__subclasses__()", "'__class__'"),
        ("getattr(s, 'upper')()", "calling 'getattr'"),
        ("format(1, 'x')", "calling 'format'"),
        ("s.format(1)", "'.format' of a str"),
        ("str.format('{}', 1)", "'.format' of a function"),
        ("'{0}'.format(a)", "'.format'"),
        ("s.upper()", "'.upper'"),
        ("[c for c in s]", "list comprehension (ListComp)"),
        ("{c: 1 for c in s}", "DictComp"),
        ("(c for c in s)", "GeneratorExp"),
        ("(lambda: 1)()", "lambda (Lambda)"),
        ("f'{a}'", "f-string (JoinedStr)"),
        ("(x := 1)", "':=' (NamedExpr)"),
        ("max(*lst)", "starred"),
        ("max(**cfg)", "keyword unpacking"),
        ("{**cfg}", "dict unpacking"),
        ("{1, 2}", "a set"),
        ("'%s' % a", "string formatting"),
        ("n << 3", "'<<'"),
        ("~n", "'~'"),
        ("b'x'", "literal b'x'"),
        ("1j", "literal 1j"),
        ("sin", "function 'sin' as a value"),
        ("python.vars(s)", "calling 'python.vars'"),
        ("__import__('os')", "'__import__'"),
        ("open('/etc/passwd')", "calling 'open'"),
        ("lst.__getitem__(0)", "'__getitem__'"),
        ("a.real", "'.real' of a float"),
        ("n[0]", "subscript of a int"),
    ],
)
def test_everything_else_is_refused_by_name(expr, needle):
    with pytest.raises(ExpressionRefused) as info:
        evaluate(expr, SYMBOLS)
    assert needle in str(info.value)
    assert expr in str(info.value)


@pytest.mark.parametrize(
    "expr, needle",
    [
        ("9**9**9", "bits"),
        ("'a' * 10**9", "repeated 1000000000 times"),
        ("10**9 * [0]", "repeated"),
        ("2 ** 5000", "bits"),
        ("(2 ** 4000) * (2 ** 4000)", "bits"),
        ("s * 2**19 + s * 2**19", "items"),
        ("1" + "+1" * 200, f"deeper than {MAX_DEPTH}"),
        ("1" * (MAX_EXPRESSION_CHARS + 1), "characters"),
        ("-" * 9000 + "1", f"deeper than {MAX_DEPTH}"),
        ("[1]" + "[0]" * 3000, f"deeper than {MAX_DEPTH}"),
    ],
)
def test_sizes_are_bounded_before_they_are_computed(expr, needle):
    start = time.perf_counter()
    with pytest.raises(ExpressionTooLarge) as info:
        evaluate(expr, SYMBOLS)
    assert needle in str(info.value)
    assert time.perf_counter() - start < 0.5


def test_checked_trees_are_cached():
    assert check_expression("a + 1") is check_expression("a + 1")


# ---- property-based: generated arithmetic, the whitelist equals Python's eval --------------------------

_leaf = st.one_of(
    st.integers(-50, 50).map(str),
    st.floats(-1e3, 1e3, allow_nan=False).map(repr),
    st.sampled_from(["a", "b", "n", "k", "flag", "pi", "e", "True", "False", "lst[0]", "lst[-1]"]),
)


def _combine(children):
    binary = st.tuples(children, st.sampled_from(["+", "-", "*", "/", "//", "%", "<", "<=", "==", "!=", ">", ">=",
                                                  "and", "or"]), children).map(lambda t: f"({t[0]} {t[1]} {t[2]})")
    power = st.tuples(children, st.integers(-3, 3)).map(lambda t: f"({t[0]}) ** {t[1]}")
    unary = st.tuples(st.sampled_from(["-", "+", "not "]), children).map(lambda t: f"({t[0]}{t[1]})")
    cond = st.tuples(children, children, children).map(lambda t: f"({t[0]} if {t[1]} else {t[2]})")
    one = st.tuples(st.sampled_from(["sin", "cos", "sqrt", "radians", "degrees", "abs", "floor", "ceil", "round",
                                     "int", "float", "atan", "exp", "log"]), children).map(lambda t: f"{t[0]}({t[1]})")
    two = st.tuples(st.sampled_from(["min", "max", "atan2", "hypot", "round"]), children, st.integers(0, 3).map(str)
                    ).map(lambda t: f"{t[0]}({t[1]}, {t[2]})")
    return st.one_of(binary, power, unary, cond, one, two)


expressions = st.recursive(_leaf, _combine, max_leaves=12)


@settings(max_examples=400, derandomize=True, deadline=None)
@given(expressions)
def test_generated_expressions_equal_pythons_eval(expr):
    try:
        expected, expected_error = python(expr), None
    except Exception as exc:  # noqa: BLE001 - the reference's own error type is the expectation
        expected, expected_error = None, type(exc)
    try:
        got, got_error = evaluate(expr, SYMBOLS), None
    except ExpressionTooLarge:
        assert expected_error is None and isinstance(expected, int) and expected.bit_length() > 4096
        return
    except Exception as exc:  # noqa: BLE001
        got, got_error = None, type(exc)
    assert got_error is expected_error, (expr, got_error, expected_error)
    if expected_error is None:
        if isinstance(expected, complex):
            assert got == expected or (math.isnan(got.real) and math.isnan(expected.real)), expr
        else:
            assert same(got, expected), (expr, got, expected)
