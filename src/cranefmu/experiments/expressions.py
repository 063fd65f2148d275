"""A tiny safe evaluator of arithmetic expressions (never ``eval``): an experiment's limits and shaper
frequencies written in terms of the scene's parameters.

Allowed: numbers; names (``g``, ``pi``, ``e``, a parameter ``component.variable``, another case's
result ``case.assertion``); ``+ - * / ** %`` and unary minus; calls of the functions in
:data:`FUNCTIONS`.  Anything else (attributes of values, subscripts, comparisons, lambdas, ...) is
refused by name, before anything is evaluated.
"""
from __future__ import annotations

import ast
import math
import operator

import numpy as np

from ..errors import CraneFmuError


class ExpressionError(CraneFmuError):
    """An expression with a syntax error, a construct not allowed, an unknown name or a math error."""


G = 9.81   # m/s2: the g of every crane FMU (physics/*.py ``g`` parameter default)
CONSTANTS = {"g": G, "pi": math.pi, "e": math.e}
FUNCTIONS = {name: getattr(math, name) for name in (
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "sqrt", "exp", "log",
    "log10", "hypot", "radians", "degrees", "floor", "ceil")}
FUNCTIONS.update({"abs": abs, "min": min, "max": max})
# the same functions element by element, for an expression of result columns (numpy arrays)
_NUMPY = {"asin": "arcsin", "acos": "arccos", "atan": "arctan", "atan2": "arctan2", "min": "minimum",
          "max": "maximum"}
VECTOR_FUNCTIONS = {name: getattr(np, _NUMPY.get(name, name)) for name in FUNCTIONS}
_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
           ast.Pow: operator.pow, ast.Mod: operator.mod}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}


def dotted(node: ast.AST) -> str | None:
    """'a.b.c' of a chain of names, else None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        head = dotted(node.value)
        return f"{head}.{node.attr}" if head is not None else None
    return None


MAX_LENGTH = 2000   # characters of one expression (the longest shipped is far below): no MemoryError
MAX_DEPTH = 200     # nesting of its tree (a + b + c ... nests one level a term): no RecursionError


def _shown(text: str) -> str:
    """``text`` quoted for a message, cut to 60 characters."""
    text = str(text)
    return repr(text) if len(text) <= 60 else repr(text[:57]) + f"... ({len(text)} characters)"


def _depth(tree: ast.AST) -> int:
    """The nesting depth of ``tree``, walked without recursion."""
    deepest, stack = 0, [(tree, 1)]
    while stack:
        node, d = stack.pop()
        deepest = max(deepest, d)
        stack += [(child, d + 1) for child in ast.iter_child_nodes(node)]
    return deepest


def parse(text: str) -> ast.Expression:
    """The checked tree of ``text`` (ExpressionError naming what is not allowed)."""
    if len(str(text)) > MAX_LENGTH:
        raise ExpressionError(f"expression {_shown(text)} is not allowed: {len(str(text))} characters, at most "
                              f"{MAX_LENGTH}")
    try:
        tree = ast.parse(str(text).strip(), mode="eval")
    except SyntaxError as err:
        raise ExpressionError(f"expression {text!r} is not valid: {err.msg}") from None
    except (RecursionError, MemoryError):
        raise ExpressionError(f"expression {_shown(text)} is not allowed: nested too deeply (at most "
                              f"{MAX_DEPTH} levels)") from None
    if _depth(tree) > MAX_DEPTH:
        raise ExpressionError(f"expression {_shown(text)} is not allowed: nested {_depth(tree)} levels deep, at most "
                              f"{MAX_DEPTH} (a sum of many terms nests one level a term)")
    for node in ast.walk(tree):
        if isinstance(node, (ast.Expression, ast.Load, ast.operator, ast.unaryop)):
            if isinstance(node, ast.operator) and type(node) not in _BINARY or \
                    isinstance(node, ast.unaryop) and type(node) not in _UNARY:
                raise ExpressionError(f"expression {text!r}: operator {type(node).__name__} is not allowed")
            continue
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                raise ExpressionError(f"expression {text!r}: only numbers are allowed as constants, "
                                      f"not {node.value!r}")
        elif isinstance(node, ast.Call):
            if not isinstance(node.func, ast.Name) or node.func.id not in FUNCTIONS or node.keywords:
                raise ExpressionError(f"expression {text!r}: only calls of {', '.join(sorted(FUNCTIONS))} "
                                      "are allowed")
        elif isinstance(node, ast.Attribute):
            if dotted(node) is None:
                raise ExpressionError(f"expression {text!r}: '.{node.attr}' is allowed only in a name "
                                      "component.variable")
        elif not isinstance(node, (ast.Name, ast.BinOp, ast.UnaryOp)):
            raise ExpressionError(f"expression {text!r}: {type(node).__name__} is not allowed (numbers, names, "
                                  "+ - * / ** % and math functions)")
    return tree


def names(text: str) -> set[str]:
    """The names (dotted as written) that ``text`` uses, functions left out."""
    out = set()
    for node in ast.walk(parse(text)):
        if isinstance(node, ast.Call):
            continue
        name = dotted(node) if isinstance(node, (ast.Name, ast.Attribute)) else None
        if name is not None and name not in FUNCTIONS:
            out.add(name)
    # a.b.c also walks a.b and a: keep the longest chains only
    return {n for n in out if not any(o != n and o.startswith(n + ".") for o in out)}


def evaluate(text: str | float | int, values: dict, vector: bool = False):
    """The value of ``text`` (a number is itself) with ``values`` (name -> number) and :data:`CONSTANTS`;
    ``vector``: values may be arrays (result columns), the functions work element by element and the
    result is an array."""
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        return float(text)
    tree = parse(text)
    functions = VECTOR_FUNCTIONS if vector else FUNCTIONS

    def ev(node: ast.AST) -> float:
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, (ast.Name, ast.Attribute)):
            name = dotted(node)
            if name in values:
                return values[name] if vector else float(values[name])
            if name in CONSTANTS:
                return CONSTANTS[name]
            raise ExpressionError(f"expression {text!r}: unknown name {name!r} (a parameter component.variable, "
                                  f"a result case.assertion, or one of {', '.join(CONSTANTS)})")
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp):
            return _UNARY[type(node.op)](ev(node.operand))
        return functions[node.func.id](*(ev(a) for a in node.args))

    try:
        if vector:
            with np.errstate(all="ignore"):
                return np.asarray(ev(tree), dtype=float)
        return float(ev(tree))
    except (ArithmeticError, ValueError, TypeError) as err:
        raise ExpressionError(f"expression {text!r} cannot be evaluated: {err}") from None
