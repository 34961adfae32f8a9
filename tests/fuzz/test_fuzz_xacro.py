"""Malformed and hostile xacro through robots.from_xacro: a named error or a robot that computes.

Files are put together from fragments a user (or an attacker) might write: properties,
arguments, macros (recursive, with missing or extra parameters), ``${}`` expressions
(arithmetic, undefined names, huge powers, dunder access, lambdas, comprehensions,
division by zero), ``$()`` substitutions (env, find of unknown packages, eval), includes
(missing, ``..``, absolute, patterns inside and outside, a NUL character, the built-in arms), conditionals, meshes, DOCTYPE/entities, and
truncation; with random arguments. Each expansion runs in xacro's child process (about
0.25 s), so the example count is small. Nothing may be written anywhere.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from fuzz_support import EXPLORE, listing, outcome
from pinarms import robots
from pinarms.robots.xacro_expand import XacroLimits

HEAD = '<?xml version="1.0"?>\n<robot name="fuzz_arm" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
ARM = ('<link name="base"/><link name="tip"/>'
       '<joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>'
       '<origin xyz="{x} 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>')

_expr = st.sampled_from([
    "0.3", "L", "L * 2", "pi / 4", "radians(30)", "undefined_name", "1/0", "9**9**9", "'a' * 10**9",
    "__import__('os').getcwd()", "().__class__.__bases__", "[x for x in range(3)]", "lambda: 1", "L if L else 0",
    "float('nan')", "float('inf')", "1e309", "-L", "abs(-0.2)", "xacro.load_yaml('/etc/passwd')", "${L}", "",
])
_sub = st.sampled_from([
    "$(arg height)", "$(arg undeclared)", "$(env HOME)", "$(optenv PATH x)", "$(find pinarms)", "$(find nothing)",
    "$(eval 1+1)", "$(cwd)", "$(anon x)",
])
_include = st.sampled_from([
    "missing.xacro", "../outside.xacro", "/etc/passwd", "$(find pinarms)/scara_mushroom.xacro",
    "$(find nothing)/x.xacro", "$(env HOME)/x.xacro", "sub/../../outside.xacro", "fuzz.xacro",
    "../*.xacro", "*.xacro", "/etc/pass*", "${'a\\x00.xacro'}",
])
_mesh = st.sampled_from(["package://fuzz/m.stl", "m.stl", "/etc/hostname", "file:///etc/hostname",
                         "package://pinarms/../../x.stl", "http://example.com/m.stl"])


@st.composite
def fragments(draw):
    kind = draw(st.sampled_from(["property", "arg", "macro", "call", "include", "if", "expr", "mesh", "arm",
                                 "scara", "text"]))
    if kind == "property":
        return f'<xacro:property name="{draw(st.sampled_from(["L", "P", "pi", "__x", ""]))}" value="${{{draw(_expr)}}}"/>'
    if kind == "arg":
        return f'<xacro:arg name="{draw(st.sampled_from(["height", "h", ""]))}" default="{draw(st.sampled_from(["0.5", "", "x"]))}"/>'
    if kind == "macro":
        body = draw(st.sampled_from(["<xacro:m/>", '<link name="${p}"/>', '<link name="m_${p}"/>', ""]))
        return f'<xacro:macro name="m" params="{draw(st.sampled_from(["p", "", "p q:=1", "*b"]))}">{body}</xacro:macro>'
    if kind == "call":
        params = draw(st.sampled_from(["", 'p="x"', 'q="1"', 'p="${L}"']))
        return f"<xacro:m {params}/>"
    if kind == "include":
        return f'<xacro:include filename="{draw(_include)}"/>'
    if kind == "if":
        return f'<xacro:if value="{draw(st.sampled_from(["1", "0", "true", "maybe", "${L}", "$(arg height)"]))}"><link name="c"/></xacro:if>'
    if kind == "expr":
        return f'<link name="e_${{{draw(_expr)}}}_{draw(_sub)}"/>'
    if kind == "mesh":
        return f'<link name="v"><visual><geometry><mesh filename="{draw(_mesh)}"/></geometry></visual></link>'
    if kind == "arm":
        return ARM.format(x=draw(st.sampled_from(["${L}", "0.2", "$(arg height)", "${1/0}", "nan"])))
    if kind == "scara":
        return '<xacro:include filename="$(find pinarms)/scara_mushroom.xacro"/><link name="floor"/>' \
               '<xacro:scara_mushroom prefix="s_" parent="floor" xyz="0 0 0" rpy="0 0 0"/>'
    return draw(st.sampled_from(["<link name='a'>", "</robot>", "<!-- x", "&amp;", "&undefined;", "${", "$(", "]]>"]))


@st.composite
def xacro_files(draw):
    body = "\n".join(draw(st.lists(fragments(), min_size=1, max_size=6)))
    text = HEAD + '<xacro:property name="L" value="0.3"/>\n' + body + "\n" + ARM.format(x="${L}") + "\n</robot>\n"
    damage = draw(st.sampled_from(["none"] * 4 + ["truncate", "entity", "doctype"]))
    if damage == "truncate":
        text = text[: draw(st.integers(0, len(text)))]
    elif damage == "entity":
        text = text.replace("<robot", '<!DOCTYPE robot [<!ENTITY a "aaaaaaaa">' + "".join(
            f'<!ENTITY {c} "{("&" + p + ";") * 10}">' for p, c in zip("abcdefg", "bcdefgh")) + "]>\n<robot", 1)
    elif damage == "doctype":
        text = text.replace("<robot", '<!DOCTYPE robot [<!ENTITY x SYSTEM "file:///etc/hostname">]>\n<robot', 1)
    return text


_args = st.dictionaries(st.sampled_from(["height", "h", "undeclared", "tcp_x"]),
                        st.one_of(st.floats(-2, 2), st.sampled_from(["0.4", "high", "", "$(env HOME)", "${1/0}"]),
                                  st.integers(-3, 3), st.none()),
                        max_size=2)

_LIMITS = XacroLimits(timeout_s=5.0, memory_bytes=256 * 2**20, output_bytes=4 * 2**20)


@settings(max_examples=25 * EXPLORE, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(text=xacro_files(), args=_args)
@example(text=HEAD + '<xacro:property name="L" value="${9**9**9}"/>' + ARM.format(x="${L}") + "</robot>", args={})
@example(text=HEAD + '<xacro:include filename="../outside.xacro"/>' + ARM.format(x="0.1") + "</robot>", args={})
@example(text=HEAD + '<xacro:macro name="m"><xacro:m/></xacro:macro><xacro:m/>' + ARM.format(x="0.1") + "</robot>",
         args={})
@example(text=HEAD + ARM.format(x="${().__class__.__bases__}") + "</robot>", args={})
@example(text=HEAD + '<xacro:arg name="height" default="0.5"/>' + ARM.format(x="$(arg height)") + "</robot>",
         args={"height": "high"})
@example(text='<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY % p SYSTEM "http://example.com/x.dtd"> %p;]>\n'
          + HEAD.split("\n", 1)[1] + ARM.format(x="0.1") + "</robot>", args={})
@example(text=HEAD + '<xacro:include filename="../*.xacro"/>' + ARM.format(x="0.1") + "</robot>", args={})
def test_malformed_xacro(tmp_path_factory, text, args):
    root = tmp_path_factory.mktemp("x")
    user = root / "user"
    user.mkdir()
    (root / "outside.xacro").write_text(HEAD + "<link name='secret'/></robot>")
    path = user / "fuzz.xacro"
    path.write_text(text)
    before = listing(root)
    robot, err = outcome(robots.from_xacro, path, limits=_LIMITS, seconds=30, **args)
    assert listing(root) == before, "expanding a xacro file wrote a file"
    if err is not None:
        assert isinstance(err, (robots.ModelError, robots.InvalidInput)), err
        return
    assert "secret" not in robot.urdf_text
    out, err = outcome(robot.fk, robot.neutral)
    assert err is None and np.all(np.isfinite(out))


# ---- the expression whitelist on its own, against xacro's real symbol table (in-process, fast) ---------

_atoms = st.sampled_from([
    "python", "xacro", "math", "pi", "L", "s", "lst", "cfg", "vars", "type", "getattr", "eval", "open", "sin",
    "xacro.abs_filename", "python.vars", "python.type", "python.getattr", "math.pi", "xacro.arg", "radians",
    "'_'", "'__'", "'_globals_'", "'os'", "0", "1", "9", "10**9", "2.5", "()", "[]", "{}", "None", "True",
])
_suffixes = st.sampled_from([
    "", ".__class__", ".__globals__", ".format", ".vars", ".type", ".abs_filename", ".pi", ".sin", ".real",
    "()", "(1)", "('x')", "(s)", "[0]", "['_'+'_globals_'+'_']", "[1:]", " ** 9 ** 9", " * 10**9", " + '_'",
    " % 1", " if 1 else 0", ".__subclasses__()",
])


@st.composite
def hostile_expressions(draw):
    parts = [draw(_atoms) + "".join(draw(st.lists(_suffixes, max_size=4)))]
    for _ in range(draw(st.integers(0, 2))):
        op = draw(st.sampled_from([" + ", " * ", " and ", " or ", ", ", "(", "["]))
        inner = draw(_atoms) + draw(_suffixes)
        parts.append(f"{op}{inner}" + (")" if op == "(" else "]" if op == "[" else ""))
    text = "".join(parts)
    wrap = draw(st.sampled_from(["{}", "[{} for c in 'ab']", "(lambda: {})()", "f'{{{}}}'", "({} := 1)", "max(*{})",
                                 "{}"]))
    return wrap.format(text)


@settings(max_examples=300 * EXPLORE)
@given(expr=hostile_expressions())
@example(expr="python.vars(python.type(python.vars(python.type(xacro.abs_filename))['_'+'_globals_'+'_']))"
              "['_'+'_get_'+'_']('os')")
def test_hostile_expressions_give_data_or_a_named_error(expr):
    import time

    import xacro

    from pinarms.robots.xacro_eval import MAX_LENGTH, ExpressionError, evaluate

    symbols = xacro.Table(xacro.create_global_symbols())
    for name, value in {"L": 0.3, "s": "arm", "lst": [1, 2], "cfg": {"a": 1}}.items():
        symbols[name] = value
    start = time.perf_counter()
    try:
        value = evaluate(expr, symbols, namespaces=(xacro.NameSpace,), attr_dicts=(xacro.YamlDictWrapper,))
    except (ExpressionError, SyntaxError, NameError, TypeError, ValueError, ZeroDivisionError, OverflowError,
            KeyError, IndexError, AttributeError):
        value = None
    assert time.perf_counter() - start < 1.0, expr
    assert isinstance(value, (bool, int, float, complex, str, list, tuple, dict, type(None))), (expr, value)
    assert not isinstance(value, xacro.NameSpace), expr
    if isinstance(value, (str, list, tuple, dict)):
        assert len(value) <= MAX_LENGTH
