"""What a xacro may compute: every ``${...}`` and ``$(eval ...)`` expression checked against an allow-list before
it is evaluated, and the whole expansion held within a time and a size limit.

A xacro expression is Python that xacro evaluates with ``eval``; xacro's own check (no ``__`` names in the top-level
code) leaves lambdas, comprehensions and attribute chains to ``__globals__`` open, through which a description runs
any command. Here each expression is parsed and refused, before anything of it runs, unless it is made of numbers,
strings, names, arithmetic, comparisons, boolean operators, conditionals, subscripts and tuple, list and dict
displays, attribute access and calls. It is then evaluated with

- every name either a property or macro parameter of the xacro, or in :data:`ALLOWED_NAMES` (math functions and
  constants, a few builtins, ``xacro.load_yaml``); xacro's other globals (``python``, ``range``, ...) refused;
- every call's function, as an object, one of the allowed functions (a property holding another is refused);
- every attribute a key of a YAML mapping, a property of an included namespace, or an allowed member of ``math``
  and ``xacro``; attributes of strings, numbers and xacro's own objects refused, names starting with ``_`` too;
- every operation that could build a large value at once (``*`` of a sequence, ``**``, ``<<``, ``%`` of a
  string) refused before it runs when its result would pass the size limit, every value measured after.

Nothing but those functions is ever called, so an expression cannot reach a module, a frame or a builtin: it reads
files only through ``xacro.load_yaml``, confined like includes (:mod:`tribokin.kinematics.urdf_xacro`), and writes
none. ``$(env)`` is refused and ``$(optenv name default)`` is its default: the environment changes no description.

Bounds (:class:`XacroLimits`): a deadline ``seconds`` after the start, the elements xacro expands (each element and
each macro call, ``elements``) and the characters it reads and produces (files, evaluated values, text, attribute,
tag and comment text: ``characters``; one value, and one file, at most a fifth of it). They are counted in the same
hooks (each expression, each element xacro walks, each text it evaluates, each file it opens), each of which checks
the deadline. They hold, rather than a child process killed at a deadline, because every step between two hooks is
bounded: an expression's operations each make a value of at most a fifth of ``characters`` (whole numbers of at
most :data:`INTEGER_BITS` bits, ``round`` to at most :data:`ROUND_DIGITS` digits, nothing called but the allowed
functions), a file is refused past a fifth of ``characters`` before it is parsed, a text before xacro's lexer
(whose time grows as its length times its ``$`` signs) reads it past :data:`LEXED_CHARACTERS`, a macro body or
block is cloned only from elements already counted, and xacro's ``replace_node``, whose time grows as the square of
the nodes it moves, is replaced by :func:`replace_node` (one pass). So the expansion stops with one error within
one such step of its limit (``benchmarks/startup.py`` times the campaign's 26 nested macros at the default), in
memory a few times ``characters`` and ``elements`` DOM nodes (about 1 KB each), and the same bytes as xacro's
own otherwise.
"""

from __future__ import annotations

import ast
import operator
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import NoReturn

#: The largest whole number an expression may build, in bits (Python writes no more than 4300 digits anyway).
INTEGER_BITS = 16_384
#: ``round(x, n)``: the most digits ``n`` may ask for, either way.
ROUND_DIGITS = 400
#: The most characters xacro's lexer may copy for one text (its length times its ``$`` signs; ``benchmarks/startup.py``
#: times the lexer at this limit).
LEXED_CHARACTERS = 2_000_000_000

_MATH = ("pi", "e", "tau", "inf", "nan", "radians", "degrees", "sin", "cos", "tan", "asin", "acos", "atan", "atan2",
         "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "sqrt", "exp", "log", "log10", "log2", "pow", "floor",
         "ceil", "fabs", "hypot", "copysign", "fmod", "remainder", "trunc", "isclose", "isfinite", "isinf", "isnan")
_BUILTINS = ("min", "max", "float", "int", "round", "str", "bool", "len", "list", "dict")
_XACRO = ("load_yaml", "arg", "dotify", "fatal")
#: Names an expression may use besides the xacro's properties and macro parameters: math functions and constants
#: (also as ``math.<name>``), a few builtins, and the namespaces ``math`` and ``xacro`` (``xacro.load_yaml``,
#: ``xacro.arg``, ``xacro.dotify``, ``xacro.fatal``; ``load_yaml`` alone as older descriptions write it).
ALLOWED_NAMES = frozenset((*_MATH, *_BUILTINS, "math", "xacro", "load_yaml", "True", "False"))
#: Names of ``$(eval ...)`` besides the xacro's arguments.
ALLOWED_EVAL_NAMES = frozenset((*_MATH, "arg", "find", "dirname", "true", "false", "True", "False"))

_REFUSED = {ast.Lambda: "lambda", ast.ListComp: "a list comprehension", ast.SetComp: "a set comprehension",
            ast.DictComp: "a dict comprehension", ast.GeneratorExp: "a generator expression",
            ast.NamedExpr: "an assignment (:=)", ast.Starred: "unpacking (*)", ast.JoinedStr: "an f-string",
            ast.Await: "await", ast.Yield: "yield", ast.YieldFrom: "yield", ast.Set: "a set"}
_ALLOWED_NODES = (ast.Expression, ast.Constant, ast.Name, ast.Load, ast.BinOp, ast.operator, ast.UnaryOp,
                  ast.unaryop, ast.BoolOp, ast.boolop, ast.Compare, ast.cmpop, ast.IfExp, ast.Subscript, ast.Slice,
                  ast.Tuple, ast.List, ast.Dict, ast.Attribute, ast.Call, ast.keyword)
_CONSTANTS = (str, int, float, bool, type(None))
_CALL, _ATTRIBUTE, _OPERATION, _CONTAINER = "__tribokin_call__", "__tribokin_attribute__", "__tribokin_op__", \
    "__tribokin_container__"


@dataclass(frozen=True)
class XacroLimits:
    """How far a xacro expansion may go before it is stopped.

    Attributes:
        seconds: wall-clock time from its start [s].
        elements: elements expanded, macro calls included.
        characters: characters read (files) and produced (evaluated values, text, attributes, tags, comments); one
            value may hold at most a fifth of them.
    """

    seconds: float = 30.0
    elements: int = 20_000
    characters: int = 50_000_000


class Budget:
    """The counts of one expansion against its :class:`XacroLimits`, its ``deadline`` a ``time.monotonic()``;
    ``stop(what, limited)`` refuses it (never returns; ``limited``: stopped at a limit of the expansion, time or
    size)."""

    def __init__(self, limits: XacroLimits, stop: Callable[[str, bool], NoReturn], deadline: float):
        self.limits, self.stop, self.deadline = limits, stop, deadline
        self.elements = self.characters = 0

    def tick(self) -> None:
        """Stop once past the deadline."""
        if time.monotonic() > self.deadline:
            self.stop(f"expansion stopped after {self.limits.seconds:g} s (the time limit of a xacro expansion)", True)

    def count(self, elements: int = 0, characters: int = 0) -> None:
        """Count elements and characters; stop past either limit or the deadline."""
        self.elements += elements
        self.characters += characters
        if self.elements > self.limits.elements:
            self.stop(f"expansion stopped past {self.limits.elements:,} elements (the size limit of a xacro "
                      "expansion)", True)
        if self.characters > self.limits.characters:
            self.stop(f"expansion stopped past {self.limits.characters:,} characters (the size limit of a xacro "
                      "expansion)", True)
        self.tick()

    def value(self, value) -> int:
        """The characters ``value`` takes written out, checked against the limit of one value."""
        size = written_size(value, self.limits.characters // 5)
        if size > self.limits.characters // 5:
            self.oversized()
        return size

    def file(self, size: int) -> None:
        """Count a file of ``size`` bytes; stop when it alone passes the limit of one value (a parser would hold the
        expansion up that long)."""
        if size > self.limits.characters // 5:
            self.stop(f"a file of more than {self.limits.characters // 5:,} bytes (the size limit of one file in a "
                      "xacro expansion)", True)
        self.count(characters=size)

    def text(self, text: str) -> None:
        """Stop before xacro lexes ``text`` if it would take too long: its lexer copies the rest of the text at each
        ``$``, a time that grows as the text's length times its ``$`` signs."""
        if len(text) * text.count("$") > LEXED_CHARACTERS:
            self.stop(f"a text of {len(text):,} characters with {text.count('$'):,} '$' (xacro would take a time "
                      "growing as their product to read it)", True)

    def oversized(self) -> NoReturn:
        """Stop: a value passes the limit of one value."""
        self.stop(f"an expression's value passes {self.limits.characters // 5:,} characters (the size limit of one "
                  "value in a xacro expansion)", False)


def written_size(value, limit: int) -> int:
    """About how many characters ``value`` (nested containers included) takes as text; stops counting past
    ``limit``."""
    size, pending = 0, [value]
    while pending and size <= limit:
        item = pending.pop()
        if isinstance(item, str):
            size += len(item)
        elif isinstance(item, bool) or item is None:
            size += 5
        elif isinstance(item, int):
            size += item.bit_length() // 3 + 2
        elif isinstance(item, dict):
            size += 2 + 4 * len(item)
            pending.extend(item.keys())
            pending.extend(dict.values(item))
        elif isinstance(item, (list, tuple)):
            size += 2 + 2 * len(item)
            pending.extend(list.__iter__(item) if isinstance(item, list) else item)
        else:
            size += 32
    return size


def _refusal(node: ast.AST, refused_name: Callable[[str], bool]) -> str | None:
    """What of the expression ``node`` is not allowed, or ``None``; ``refused_name``: whether a name is one of
    xacro's globals that is not allowed (named in the answer: none is the file's own)."""
    for child in ast.walk(node):
        kind = _REFUSED.get(type(child))
        if kind is not None:
            return f"{kind} is not allowed"
        if not isinstance(child, _ALLOWED_NODES) or isinstance(child, ast.MatMult):
            return f"{type(child).__name__} is not allowed"
        if isinstance(child, ast.Constant) and not isinstance(child.value, _CONSTANTS):
            return f"a {type(child.value).__name__} constant is not allowed"
        if isinstance(child, ast.Attribute) and child.attr.startswith("_"):
            return "an attribute whose name starts with '_' is not allowed"
        if isinstance(child, ast.keyword) and child.arg is None:
            return "unpacking (**) is not allowed"
        if isinstance(child, ast.Name) and child.id.startswith("__"):
            return "a name starting with '__' is not allowed"
        if isinstance(child, ast.Name) and refused_name(child.id):
            return f"xacro's global '{child.id}' is not allowed"
    return None


class _Guarded(ast.NodeTransformer):
    """The expression with each call, attribute, operation and subscripted value going through the guard's
    functions (:class:`Guard`)."""

    @staticmethod
    def _helper(name: str, node: ast.AST, args: list, keywords=()) -> ast.Call:
        return ast.copy_location(ast.Call(ast.Name(name, ast.Load()), args, list(keywords)), node)

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        return self._helper(_CALL, node, [node.func, *node.args], node.keywords)

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        self.generic_visit(node)
        return self._helper(_ATTRIBUTE, node, [node.value, ast.Constant(node.attr)])

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        return self._helper(_OPERATION, node, [ast.Constant(type(node.op).__name__), node.left, node.right])

    def visit_Subscript(self, node: ast.Subscript) -> ast.AST:
        self.generic_visit(node)
        node.value = self._helper(_CONTAINER, node.value, [node.value])
        return node


_OPERATIONS = {"Add": operator.add, "Sub": operator.sub, "Mult": operator.mul, "Div": operator.truediv,
               "FloorDiv": operator.floordiv, "Mod": operator.mod, "Pow": operator.pow, "LShift": operator.lshift,
               "RShift": operator.rshift, "BitOr": operator.or_, "BitXor": operator.xor, "BitAnd": operator.and_}


class Guard:
    """The checked evaluation of one xacro expansion: :meth:`safe_eval` in place of xacro's, :meth:`substitution_eval`
    in place of its ``$(eval ...)``, and xacro's ``eval_all`` and ``eval_text`` counted (:meth:`counted`).

    Args:
        xacro: the xacro module (its ``Table``, ``NameSpace``, ``YamlDictWrapper`` and globals).
        budget: the expansion's :class:`Budget`; its ``stop`` refuses an expression too.
        find: the ``find`` of ``$(eval find('pkg'))``.
    """

    def __init__(self, xacro, budget: Budget, find: Callable[[str], str]):
        self.xacro, self.budget, self.find = xacro, budget, find
        self.root = root = xacro._global_symbols
        self.members = {id(space): frozenset() for space in root.values() if isinstance(space, xacro.NameSpace)}
        self.members.update({id(root["math"]): frozenset(_MATH), id(root["xacro"]): frozenset(_XACRO)})
        self.functions = frozenset(id(f) for f in [*(root[n] for n in (*_MATH, *_BUILTINS, "load_yaml")),
                                                   *(root["xacro"][n] for n in _XACRO)] if callable(f))
        self.helpers = {"__builtins__": {}, _CALL: self._caller(self.functions), _ATTRIBUTE: self._attribute,
                        _OPERATION: self._operation, _CONTAINER: self._container}

    def counted(self, eval_all, eval_text) -> tuple[Callable, Callable]:
        """xacro's ``eval_all`` counting each element (its tag, attribute names and comments), and its ``eval_text``
        counting each text it gives (attribute values, text, evaluated strings)."""
        budget = self.budget

        def counted_eval_all(node, macros, symbols):
            budget.count(1, len(node.tagName) + sum(map(len, node.attributes.keys())) + sum(
                len(child.data) for child in node.childNodes
                if child.nodeType not in (child.ELEMENT_NODE, child.TEXT_NODE) and hasattr(child, "data")))
            return eval_all(node, macros, symbols)

        def counted_eval_text(text, symbols):
            if isinstance(text, str):
                budget.text(text)
            value = eval_text(text, symbols)
            budget.count(characters=len(value) if isinstance(value, str) else 0)
            return value

        return counted_eval_all, counted_eval_text

    def environment(self, name: str) -> NoReturn:
        """xacro's ``$(env name)``: refused (the environment changes no description)."""
        self._refuse("$(env ...) is not allowed: the environment changes no robot description; give the value as a "
                     "xacro argument")

    @staticmethod
    def optional_environment(name: str, default: str = "") -> str:
        """xacro's ``$(optenv name default)``: the default, whatever the environment holds."""
        return default

    def _checked(self, expression: str, refused_name: Callable[[str], bool], form: str = "${...}"):
        """The code of ``expression`` (written as ``form``) guarded (:class:`_Guarded`), once it holds nothing
        refused."""
        self.budget.tick()
        tree = ast.parse(expression.strip(), "<expression>", "eval")
        refusal = _refusal(tree, refused_name)
        if refusal is not None:
            self._refuse(f"{refusal} in {form} (a xacro expression may use numbers, strings, its properties, "
                         "arithmetic, comparisons, conditionals and math functions)")
        return compile(ast.fix_missing_locations(_Guarded().visit(tree)), "<expression>", "eval")

    def safe_eval(self, expr: str, globals, locals=None):
        """xacro's ``safe_eval``: ``expr`` checked, then evaluated with the properties of the table ``globals``."""
        def refused_name(name: str) -> bool:
            return name not in ALLOWED_NAMES and name in self.root and not self._defined(globals, name)

        code = self._checked(expr, refused_name)
        value = eval(code, dict(self.helpers), globals)  # noqa: S307 - checked and guarded above
        self.budget.count(characters=self.budget.value(value))
        return value

    def substitution_eval(self, expression: str, context: dict) -> str:
        """xacro's ``$(eval ...)``: ``expression`` checked, then evaluated with the xacro's arguments and
        :data:`ALLOWED_EVAL_NAMES`."""
        from xacro import substitution_args as args

        arguments = context.setdefault("arg", {})
        functions = {name: value for name, value in args._eval_dict.items() if name in ALLOWED_EVAL_NAMES}
        functions.update(find=self.find, arg=lambda name: args.convert_value(args._eval_arg(name, arguments), "auto"),
                         dirname=lambda: args._eval_dirname(context["filename"]))
        code = self._checked(expression, lambda name: name in args._eval_dict and name not in ALLOWED_EVAL_NAMES,
                             "$(eval ...)")
        helpers = {**self.helpers,
                   _CALL: self._caller(self.functions | {id(f) for f in functions.values() if callable(f)})}
        value = str(eval(code, helpers, args._DictWrapper(arguments, functions)))  # noqa: S307 - checked, guarded
        self.budget.count(characters=self.budget.value(value))
        return value

    def _refuse(self, what: str) -> NoReturn:
        self.budget.stop(what, False)

    def _defined(self, table, name: str) -> bool:
        """Whether ``name`` is a property or macro parameter of the xacro: in ``table`` or its parents below
        xacro's globals."""
        while isinstance(table, self.xacro.Table) and id(table) not in self.members:
            if dict.__contains__(table, name):
                return True
            table = table.parent
        return False

    def _caller(self, functions: frozenset) -> Callable:
        """The guard of a call: ``function`` one of ``functions`` (by identity), keywords only for ``dict``."""
        def call(function, /, *args, **kwargs):
            if id(function) not in functions:
                self._refuse("a call of a function outside the allowed ones is not allowed")
            if kwargs and function is not self.root["dict"]:
                self._refuse("keyword arguments are not allowed (but in dict(...))")
            if function is self.root["round"] and len(args) > 1 and isinstance(args[1], int) and \
                    abs(args[1]) > ROUND_DIGITS:
                self._refuse(f"round() to more than {ROUND_DIGITS} digits is not allowed")
            return self._checked_value(function(*args, **kwargs))

        return call

    def _attribute(self, value, name: str):
        if isinstance(value, self.xacro.YamlDictWrapper):
            return value.__getattr__(name)  # a key, as xacro's dotted access to YAML
        if isinstance(value, self.xacro.NameSpace):
            members = self.members.get(id(value))
            if name in members if members is not None else self._defined(value, name):
                return value[name]
            self._refuse("an attribute that is neither an allowed function nor a property of the namespace is not "
                         "allowed")
        self._refuse(f"an attribute of a {type(value).__name__} is not allowed (only keys of YAML mappings and "
                     "properties of namespaces)")

    def _container(self, value):
        if isinstance(value, self.xacro.Table):
            self._refuse("a subscript of a namespace is not allowed (write namespace.property)")
        return value

    def _operation(self, name: str, left, right):
        limit = self.budget.limits.characters // 5
        if name == "Mult":
            sequence, times = (left, right) if isinstance(left, (str, list, tuple)) else (right, left)
            if isinstance(sequence, (str, list, tuple)) and isinstance(times, int) and \
                    written_size(sequence, limit) * times > limit:
                self.budget.oversized()
        elif name in ("Pow", "LShift") and isinstance(left, int) and isinstance(right, int) and abs(left) > 1 and \
                right * (1 if name == "LShift" else abs(left).bit_length() - 1) > INTEGER_BITS:
            self._refuse(f"a whole number of more than {INTEGER_BITS:,} bits is not allowed")
        elif name == "Mod" and isinstance(left, str):
            self._refuse("string formatting with % is not allowed")
        return self._checked_value(_OPERATIONS[name](left, right))

    def _checked_value(self, value):
        if isinstance(value, int) and value.bit_length() > INTEGER_BITS:
            self._refuse(f"a whole number of more than {INTEGER_BITS:,} bits is not allowed")
        self.budget.value(value)
        return value


def replace_node(node, by, content_only: bool = False) -> None:
    """xacro's ``replace_node`` (``node`` replaced by the nodes ``by``, or by their children with ``content_only``;
    ``None``: removed) in one pass over its parent's children: xacro's own inserts them one by one, each a search of
    the parent's children, which makes a macro that expands to many elements take a time that grows as their square,
    in one step no hook sees."""
    from xml.dom.minidom import _clear_id_cache

    parent, moved = node.parentNode, []
    for item in [] if by is None else by if isinstance(by, list) else [by]:
        if content_only:
            moved.extend(item.childNodes)
            item.childNodes[:] = []
            _clear_id_cache(item)
        else:
            if item.parentNode is not None:
                item.parentNode.removeChild(item)
            moved.append(item)
    index = parent.childNodes.index(node)
    parent.childNodes[index:index + 1] = moved
    for child in moved:
        child.parentNode = parent
    neighbours = [parent.childNodes[index - 1] if index else None, *moved,
                  parent.childNodes[index + len(moved)] if index + len(moved) < len(parent.childNodes) else None]
    for before, after in zip(neighbours, neighbours[1:], strict=False):
        if before is not None:
            before.nextSibling = after
        if after is not None:
            after.previousSibling = before
    node.parentNode = node.previousSibling = node.nextSibling = None
    _clear_id_cache(parent)
