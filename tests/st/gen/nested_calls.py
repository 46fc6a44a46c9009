# Generates tests/st/nested_calls*.st and tests/st/test_nested_calls*.st: every outer call
# kind x inner call kind x argument position. Run `python3 tests/st/gen/nested_calls.py
# tests/st` after changing it; the ctest st.nested_calls_generated checks the files match.
import sys
out_dir = sys.argv[1]

INNER = [  # (id, description, expression yielding 34)
  ("fn",     "a FUNCTION",                         "FAdd(x := 3, y := 4)"),
  ("meth",   "a METHOD",                           "o.MAdd(x := 3, y := 4)"),
  ("prop",   "a PROPERTY getter",                  "o.Count"),
  ("itf",    "an interface method",                "itf.MAdd(3, 4)"),
  ("itfprop","an interface PROPERTY getter",       "itf.Count"),
  ("this",   "a THIS^ method",                     "THIS^.MAdd(x := 3, y := 4)"),
  ("super",  "a SUPER^ method",                    "SUPER^.MAdd(x := 3, y := 4)"),
  ("bare",   "an own method by its bare name",     "MAdd(3, 4)"),
  ("stdm",   "a standard function over a method",  "MAX(o.MAdd(x := 3, y := 4), 0)"),
  ("fvia",   "a FUNCTION whose body calls a method", "FViaItf(itf)"),
  ("nest",   "a METHOD nested in itself",          "o.MAdd(x := o.MAdd(x := 0, y := 3), y := o.Count - 30)"),
  ("rec",    "a recursive METHOD four levels deep", "o.Rec(n := 4, k := 34)"),
]

def enc3(a, b, c): return a * 10000 + b * 100 + c

# Outer kinds with three argument positions. Each returns (statements, result expression,
# expected value function of the argument triple).
def args3(pos, inner):
  vals = ["v1", "v2", "v3"]
  vals[pos] = inner
  nums = [1, 2, 3]
  nums[pos] = 34
  return vals, nums

OUTER = []
def outer(id_, desc, positions, build):
  OUTER.append((id_, desc, positions, build))

outer("fn", "a FUNCTION", 3, lambda p, i: (lambda v, n: ([f"res := F3(a := {v[0]}, b := {v[1]}, c := {v[2]});"], enc3(*n)))(*args3(p, i)))
outer("fb", "an FB instance call", 3, lambda p, i: (lambda v, n: ([f"fb3(a := {v[0]}, b := {v[1]}, c := {v[2]});", "res := fb3.q;"], enc3(*n)))(*args3(p, i)))
outer("meth", "a METHOD", 3, lambda p, i: (lambda v, n: ([f"res := o.M3(a := {v[0]}, b := {v[1]}, c := {v[2]});"], enc3(*n)))(*args3(p, i)))
outer("itf", "an interface method", 3, lambda p, i: (lambda v, n: ([f"res := itf.M3(a := {v[0]}, b := {v[1]}, c := {v[2]});"], enc3(*n)))(*args3(p, i)))
outer("this", "a THIS^ method", 3, lambda p, i: (lambda v, n: ([f"res := THIS^.M3(a := {v[0]}, b := {v[1]}, c := {v[2]});"], enc3(*n)))(*args3(p, i)))
outer("super", "a SUPER^ method", 3, lambda p, i: (lambda v, n: ([f"res := SUPER^.M3(a := {v[0]}, b := {v[1]}, c := {v[2]});"], enc3(*n)))(*args3(p, i)))
outer("bare", "an own method by its bare name", 3, lambda p, i: (lambda v, n: ([f"res := M3(a := {v[0]}, b := {v[1]}, c := {v[2]});"], enc3(*n)))(*args3(p, i)))
outer("std", "a standard function", 3, lambda p, i: (lambda v, n: ([f"res := ADD({v[0]} * 10000, {v[1]} * 100, {v[2]});"], enc3(*n)))(*args3(p, i)))

# VAR_IN_OUT in the middle: the inner call sits in the first input, in the index of the
# in-out variable, or in the last input. Result: callee's value * 100 + the in-out variable after the call.
def io_case(call_fmt, after=""):
  def build(p, i):
    a, idx, c = "v1", "2", "v3"
    na, nc = 1, 3
    if p == 0: a, na = i, 34
    if p == 1: idx = f"{i} - 32"
    if p == 2: c, nc = i, 34
    stmts = [call_fmt.format(a=a, idx=idx, c=c)]
    if after: stmts.append(after)
    stmts.append("res := res * 100 + arr[2];")
    return stmts, enc3(na, 2, nc) * 100 + 3
  return build
outer("fnio", "a FUNCTION with a VAR_IN_OUT", 3, io_case("res := FIo(a := {a}, io := arr[{idx}], c := {c});"))
outer("fbio", "an FB call with a VAR_IN_OUT", 3, io_case("fbio(a := {a}, io := arr[{idx}], c := {c});", "res := fbio.q;"))
outer("methio", "a METHOD with a VAR_IN_OUT", 3, io_case("res := o.MIo(a := {a}, io := arr[{idx}], c := {c});"))

# Outputs: the inner call in the first input, the second input, or the index of the first
# output's destination (the second output and the result must survive it).
# Result: callee's result * 10^8 + arr[3] * 10^4 + rv.
def out_case(call_fmt, res_expr):
  def build(p, i):
    a, b, idx = "v1", "v2", "3"
    na, nb = 1, 2
    if p == 0: a, na = i, 34
    if p == 1: b, nb = i, 34
    if p == 2: idx = f"{i} - 31"
    stmts = [call_fmt.format(a=a, b=b, idx=idx), f"res := {res_expr};", "res := res * 100000000 + arr[3] * 10000 + rv;"]
    return stmts, (na * 100 + nb) * 100000000 + (nb * 100 + na) * 10000 + (na + nb)
  return build
outer("fnout", "a FUNCTION with outputs", 3, out_case("fres := FOut(a := {a}, b := {b}, q => arr[{idx}], r => rv);", "fres"))
outer("fbout", "an FB call with outputs", 3, out_case("fbo(a := {a}, b := {b}, q => arr[{idx}], r => rv);", "fbo.s"))
outer("methout", "a METHOD with outputs", 3, out_case("fres := o.MOut(a := {a}, b := {b}, q => arr[{idx}], r => rv);", "fres"))

# PROPERTY setters take one value.
outer("pset", "a PROPERTY setter", 1, lambda p, i: ([f"o.Last := {i} + v1;", "res := o.Last;"], 35))
outer("itfpset", "an interface PROPERTY setter", 1, lambda p, i: ([f"itf.Last := {i} + v1;", "res := itf.Last;"], 35))

POS = ["first", "middle", "last"]

PRELUDE = ("""(* {topic}.st: calls nested in the arguments of {what},
   for test_{topic}.st. Every callee with three inputs returns a * 10000 + b * 100 + c and
   every inner call yields 34, so an argument lost to (or overwritten by) a nested call's
   frame shows in the result.
   The cases are the methods C_<outer>_<inner> of Harness (so that THIS^, SUPER^ and bare
   method names are available); pos 1, 2, 3 puts the inner call in the first, middle or last
   argument. Generated: one case per outer call kind x inner call kind. *)

INTERFACE IWork
METHOD MAdd : DINT
VAR_INPUT x, y : DINT; END_VAR
END_METHOD
METHOD M3 : DINT
VAR_INPUT a, b, c : DINT; END_VAR
END_METHOD
METHOD MIo : DINT
VAR_INPUT a : DINT; END_VAR
VAR_IN_OUT io : DINT; END_VAR
VAR_INPUT c : DINT; END_VAR
END_METHOD
METHOD MOut : DINT
VAR_INPUT a, b : DINT; END_VAR
VAR_OUTPUT q, r : DINT; END_VAR
END_METHOD
PROPERTY Count : DINT
GET END_GET
END_PROPERTY
PROPERTY Last : DINT
GET END_GET
SET END_SET
END_PROPERTY
END_INTERFACE

FUNCTION FAdd : DINT
VAR_INPUT x, y : DINT; END_VAR
FAdd := x * 10 + y;
END_FUNCTION

FUNCTION F3 : DINT
VAR_INPUT a, b, c : DINT; END_VAR
F3 := a * 10000 + b * 100 + c;
END_FUNCTION

FUNCTION FIo : DINT
VAR_INPUT a : DINT; END_VAR
VAR_IN_OUT io : DINT; END_VAR
VAR_INPUT c : DINT; END_VAR
FIo := a * 10000 + io * 100 + c;
io := io + 1;
END_FUNCTION

FUNCTION FOut : DINT
VAR_INPUT a, b : DINT; END_VAR
VAR_OUTPUT q, r : DINT; END_VAR
FOut := a * 100 + b;
q := b * 100 + a;
r := a + b;
END_FUNCTION

(* A function whose own body calls a method: that method's frame is taken while the
   caller may be assembling another call's arguments. *)
FUNCTION FViaItf : DINT
VAR_INPUT w : IWork; END_VAR
FViaItf := w.MAdd(x := 3, y := w.Count - 30);
END_FUNCTION

(* Increments its in-out argument and returns 0: shows when an argument is read. *)
FUNCTION IncX : DINT
VAR_IN_OUT x : DINT; END_VAR
x := x + 1;
IncX := 0;
END_FUNCTION

FUNCTION_BLOCK FB3
VAR_INPUT a, b, c : DINT; END_VAR
VAR_OUTPUT q : DINT; END_VAR
q := a * 10000 + b * 100 + c;
END_FUNCTION_BLOCK

FUNCTION_BLOCK FBIo
VAR_INPUT a : DINT; END_VAR
VAR_IN_OUT io : DINT; END_VAR
VAR_INPUT c : DINT; END_VAR
VAR_OUTPUT q : DINT; END_VAR
q := a * 10000 + io * 100 + c;
io := io + 1;
END_FUNCTION_BLOCK

FUNCTION_BLOCK FBOut
VAR_INPUT a, b : DINT; END_VAR
VAR_OUTPUT q, r, s : DINT; END_VAR
s := a * 100 + b;
q := b * 100 + a;
r := a + b;
END_FUNCTION_BLOCK

FUNCTION_BLOCK Worker IMPLEMENTS IWork
VAR
  tens : DINT := 3;
  ones : DINT := 4;
  lastVal : DINT;
END_VAR
VAR_OUTPUT
  kept : DINT;
END_VAR
METHOD MAdd : DINT
VAR_INPUT x, y : DINT; END_VAR
MAdd := x * 10 + y;
END_METHOD
METHOD M3 : DINT
VAR_INPUT a, b, c : DINT; END_VAR
M3 := a * 10000 + b * 100 + c;
END_METHOD
METHOD Keep
VAR_INPUT a, b, c : DINT; END_VAR
kept := a * 10000 + b * 100 + c;
END_METHOD
METHOD MIo : DINT
VAR_INPUT a : DINT; END_VAR
VAR_IN_OUT io : DINT; END_VAR
VAR_INPUT c : DINT; END_VAR
MIo := a * 10000 + io * 100 + c;
io := io + 1;
END_METHOD
METHOD MOut : DINT
VAR_INPUT a, b : DINT; END_VAR
VAR_OUTPUT q, r : DINT; END_VAR
MOut := a * 100 + b;
q := b * 100 + a;
r := a + b;
END_METHOD
(* Rec(n, k) = k, computed through n nested calls whose other arguments must survive. *)
METHOD Rec : DINT
VAR_INPUT n, k : DINT; END_VAR
IF n <= 0 THEN
  Rec := k;
ELSE
  Rec := THIS^.M3(a := n, b := THIS^.Rec(n := n - 1, k := k), c := n) - n * 10000 - n;
  Rec := Rec / 100;
END_IF;
END_METHOD
PROPERTY Count : DINT
GET
  Count := tens * 10 + ones;
END_GET
END_PROPERTY
PROPERTY Last : DINT
GET
  Last := lastVal;
END_GET
SET
  lastVal := Last;
END_SET
END_PROPERTY
END_FUNCTION_BLOCK

(* SUPER^ calls land here. *)
FUNCTION_BLOCK HarnessBase
METHOD MAdd : DINT
VAR_INPUT x, y : DINT; END_VAR
MAdd := x * 10 + y;
END_METHOD
METHOD M3 : DINT
VAR_INPUT a, b, c : DINT; END_VAR
M3 := a * 10000 + b * 100 + c;
END_METHOD
END_FUNCTION_BLOCK

FUNCTION_BLOCK Harness EXTENDS HarnessBase
VAR
  o : Worker;
  itf : IWork;
  fb3 : FB3;
  fbio : FBIo;
  fbo : FBOut;
  arr : ARRAY[0..9] OF DINT;
  rv : DINT;
  t34 : DINT := 34;
  mineVal : DINT;
END_VAR

(* Overrides: THIS^ and bare names reach these, SUPER^ the base's. *)
METHOD MAdd : DINT
VAR_INPUT x, y : DINT; END_VAR
MAdd := x * 10 + y;
END_METHOD
METHOD M3 : DINT
VAR_INPUT a, b, c : DINT; END_VAR
M3 := a * 10000 + b * 100 + c;
END_METHOD
PROPERTY Mine : DINT
GET
  Mine := mineVal;
END_GET
SET
  mineVal := Mine;
END_SET
END_PROPERTY

METHOD Prepare
VAR i : INT; END_VAR
itf := o;
FOR i := 0 TO 9 DO
  arr[i] := i;
END_FOR;
rv := 0;
END_METHOD
""")

METHOD_OUTER = {"meth", "itf", "this", "super", "bare", "methio", "methout", "pset", "itfpset"}

def generate(topic, what, outers, extra_src, head):
  src = [PRELUDE.replace("{topic}", topic).replace("{what}", what)]
  tests = []
  for oid, odesc, npos, build in outers:
    for iid, idesc, iexpr in INNER:
      name = f"C_{oid}_{iid}"
      body = []
      exp = []
      for p in range(npos):
        stmts, val = build(p, iexpr)
        body.append(f"{p + 1}:")
        body += ["  " + s for s in stmts]
        exp.append(val)
      import re
      text = "\n".join(body)
      decls = ["res : LINT;"] + [d for v, d in [("fres", "fres : DINT;"), ("v1", "v1 : DINT := 1;"), ("v2", "v2 : DINT := 2;"), ("v3", "v3 : DINT := 3;")] if re.search(r"\b" + v + r"\b", text)]
      body = [f"METHOD {name} : LINT", "VAR_INPUT pos : INT; END_VAR", "VAR " + " ".join(decls) + " END_VAR",
              "Prepare();", "CASE pos OF"] + body + ["END_CASE;", f"{name} := res;", "END_METHOD", ""]
      src += body
      t = [f"TEST '{odesc} with {idesc} in each argument'", "VAR h : Harness; END_VAR"]
      for p, val in enumerate(exp):
        where = POS[p] if npos == 3 else "value"
        t.append(f"ASSERT_EQ(h.{name}({p + 1}), LINT#{val}, '{where} argument');")
      t += ["END_TEST", ""]
      tests += t
  src.append("END_FUNCTION_BLOCK")
  src.append(extra_src)
  open(f"{out_dir}/{topic}.st", "w").write("\n".join(src) + "\n")
  open(f"{out_dir}/test_{topic}.st", "w").write("\n".join([head] + tests))
  return len(tests)


# A method returning its own input count, for the call from the issue.
COUNTER1 = ("""
FUNCTION_BLOCK Counter1
METHOD M : DINT
VAR_INPUT a, b : DINT; END_VAR
M := a * 100 + b;
END_METHOD
PROPERTY Count : DINT
GET
  Count := 1;
END_GET
END_PROPERTY
END_FUNCTION_BLOCK
""")

HEAD = ("""(* test_nested_calls.st: a call in an argument of a METHOD call or a PROPERTY setter
   must not disturb the arguments already passed, the outputs still to be read, or the
   result: the call from the bug report, the same method nested in itself, arguments read
   left to right, recursion, then every outer call kind x every inner call kind x first,
   middle and last argument (the generated cases of nested_calls.st). *)

TEST 'a PROPERTY getter in the second argument of a METHOD'
VAR c : Counter1; END_VAR
ASSERT_EQ(c.M(a := 5, b := c.Count), 501);
ASSERT_EQ(c.M(5, c.Count), 501);
ASSERT_EQ(c.M(a := c.Count, b := 5), 105);
END_TEST

TEST 'the same METHOD nested in itself'
VAR c : Counter1; END_VAR
ASSERT_EQ(c.M(a := c.M(a := 1, b := 2), b := c.Count), 10201);
ASSERT_EQ(c.M(a := c.M(a := 1, b := 2), b := c.M(a := 0, b := c.Count)), 10201);
ASSERT_EQ(c.M(a := c.M(a := c.M(a := 1, b := c.Count), b := c.M(a := 0, b := 2)), b := c.Count), 1010201);
END_TEST

TEST 'arguments are read left to right, each in its turn'
VAR h : Harness; w : Worker; i : IWork; f : FB3; x : DINT; END_VAR
i := w;
x := 5;
ASSERT_EQ(F3(a := x, b := IncX(x), c := x), 50006, 'FUNCTION');
x := 5;
ASSERT_EQ(w.M3(a := x, b := IncX(x), c := x), 50006, 'METHOD');
x := 5;
ASSERT_EQ(i.M3(a := x, b := IncX(x), c := x), 50006, 'interface method');
x := 5;
f(a := x, b := IncX(x), c := x);
ASSERT_EQ(f.q, 50006, 'FB instance');
END_TEST

TEST 'a recursive METHOD keeps the arguments of every level'
VAR w : Worker; END_VAR
ASSERT_EQ(w.Rec(n := 0, k := 34), 34);
ASSERT_EQ(w.Rec(n := 1, k := 34), 34);
ASSERT_EQ(w.Rec(n := 9, k := 77), 77);
END_TEST
""")
HEAD_FN = """(* test_nested_calls_fn.st: a call in an argument of a FUNCTION, an FB instance call or a
   standard function, in a VAR_IN_OUT or in an output's destination must not disturb the
   other arguments, outputs or the result: every outer call kind x every inner call kind x
   first, middle and last argument (the generated cases of nested_calls_fn.st). *)
"""

n1 = generate("nested_calls", "METHOD calls and PROPERTY setters",
              [o for o in OUTER if o[0] in METHOD_OUTER], COUNTER1, HEAD)
n2 = generate("nested_calls_fn", "FUNCTIONs, FB instances and standard functions",
              [o for o in OUTER if o[0] not in METHOD_OUTER], "", HEAD_FN)
print(n1, n2)
