#!/usr/bin/env python3
"""Check FMI 2.0 modelDescription.xml files against the rules of the FMI 2.0 standard.

usage: fmi2_md_check.py FILE.xml...

Prints "FILE: ok (N variables)" per valid file, or one line "FILE: WHERE: RULE" per
violation. Exit status: 0 all files valid, 1 a violation, 2 usage error or a file that
cannot be read or is not XML.

The rules are written from the text of the standard (FMI 2.0.x): section 2.2 "FMI
Description Schema" (2.2.1 fmiModelDescription ... 2.2.9 variable naming) and section
4.3.1 (CoSimulation). Comments give the section a rule comes from. Only the Python
standard library is used; no schema file is needed.
"""
import re
import sys
import xml.etree.ElementTree as ET

XSI = '{http://www.w3.org/2001/XMLSchema-instance}'  # xsi:* attributes are always allowed


# --- Lexical forms of the XML Schema types the standard uses -------------------------
def _text(what, test):
    test.what = what
    return test


STR = _text('a string', lambda s: True)
BOOL = _text('a boolean (true, false, 1, 0)', lambda s: s.strip() in ('true', 'false', '1', '0'))
UINT = _text('an unsigned 32-bit integer',
             lambda s: re.fullmatch(r'\+?\d+', s.strip()) is not None and int(s) < 2**32)
INT = _text('a 32-bit integer',
            lambda s: re.fullmatch(r'[+-]?\d+', s.strip()) is not None and -2**31 <= int(s) < 2**31)
# 2.2: NaN and the infinities are not allowed as values in the XML file.
DOUBLE = _text('a finite number',
               lambda s: re.fullmatch(r'[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?', s.strip()) is not None)
DATETIME = _text('a date and time like 2009-12-08T14:33:22Z',
                 lambda s: re.fullmatch(r'-?\d{4,}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?(Z|[+-]\d\d:\d\d)?',
                                        s.strip()) is not None)
UINT_LIST = _text('a list of unsigned integers', lambda s: all(UINT(x) for x in s.split()))
KINDS = ('dependent', 'constant', 'fixed', 'tunable', 'discrete')
KIND_LIST = _text('a list of ' + ', '.join(KINDS), lambda s: all(k in KINDS for k in s.split()))


def ONE_OF(*values):
    return _text('one of ' + ', '.join(values), lambda s: s.strip() in values)


# 4.3.1: modelIdentifier is "a short class name according to C syntax".
C_IDENT = _text('a C identifier', lambda s: re.fullmatch(r'[A-Za-z_][A-Za-z0-9_]*', s) is not None)

# 2.2.9: structured names (the Modelica identifier syntax, with der(...) and [i,j]).
_Q = r"'(?:[A-Za-z0-9_!#$%&()*+,\-./:;<>=?@\[\]^{}|~ ]|\\['\"?\\abfnrtv])+'"
_IDENT = rf"(?:[A-Za-z_]\w*|{_Q})(?:\[\d+(?:,\d+)*\])?"
_IDENT = rf"{_IDENT}(?:\.{_IDENT})*"
STRUCTURED_NAME = re.compile(rf"{_IDENT}|der\({_IDENT}(?:,\d+)?\)", re.ASCII)

# --- Attributes and children of the elements (2.2.1 - 2.2.8, 4.3.1) ---------------------
CAUSALITIES = ('parameter', 'calculatedParameter', 'input', 'output', 'local', 'independent')
VARIABILITIES = ('constant', 'fixed', 'tunable', 'discrete', 'continuous')
ROOT_ATTRS = dict(fmiVersion=STR, modelName=STR, guid=STR, description=STR, author=STR,
                  version=STR, copyright=STR, license=STR, generationTool=STR,
                  generationDateAndTime=DATETIME, variableNamingConvention=ONE_OF('flat', 'structured'),
                  numberOfEventIndicators=UINT)
# 2.2.1: ModelExchange and CoSimulation come first (the standard's schema lets them appear in
# either order), then the others in this order; ModelVariables and ModelStructure are required.
ROOT_CHILDREN = [('ModelExchange', 'CoSimulation'), 'UnitDefinitions', 'TypeDefinitions',
                 'LogCategories', 'DefaultExperiment', 'VendorAnnotations', 'ModelVariables',
                 'ModelStructure']
_FLAGS = ('needsExecutionTool', 'canBeInstantiatedOnlyOncePerProcess', 'canNotUseMemoryManagementFunctions',
          'canGetAndSetFMUstate', 'canSerializeFMUstate', 'providesDirectionalDerivative')
ME_ATTRS = dict(modelIdentifier=C_IDENT, completedIntegratorStepNotNeeded=BOOL, **{f: BOOL for f in _FLAGS})
CS_ATTRS = dict(modelIdentifier=C_IDENT, canHandleVariableCommunicationStepSize=BOOL, canInterpolateInputs=BOOL,
                maxOutputDerivativeOrder=UINT, canRunAsynchronuously=BOOL,  # sic, the standard's spelling
                **{f: BOOL for f in _FLAGS})
REAL_ATTRS = dict(quantity=STR, unit=STR, displayUnit=STR, relativeQuantity=BOOL, min=DOUBLE, max=DOUBLE,
                  nominal=DOUBLE, unbounded=BOOL)
INT_ATTRS = dict(quantity=STR, min=INT, max=INT)
TYPES = ('Real', 'Integer', 'Boolean', 'String', 'Enumeration')
SIMPLE_TYPE_ATTRS = dict(Real=REAL_ATTRS, Integer=INT_ATTRS, Boolean={}, String={},
                         Enumeration=dict(quantity=STR))
VAR_TYPE_ATTRS = dict(Real=dict(declaredType=STR, **REAL_ATTRS, start=DOUBLE, derivative=UINT, reinit=BOOL),
                      Integer=dict(declaredType=STR, **INT_ATTRS, start=INT),
                      Boolean=dict(declaredType=STR, start=BOOL),
                      String=dict(declaredType=STR, start=STR),
                      Enumeration=dict(declaredType=STR, **INT_ATTRS, start=INT))
VAR_ATTRS = dict(name=STR, valueReference=UINT, description=STR, causality=ONE_OF(*CAUSALITIES),
                 variability=ONE_OF(*VARIABILITIES), initial=ONE_OF('exact', 'approx', 'calculated'),
                 canHandleMultipleSetPerTimeInstant=BOOL)
# 2.2.7: value references are unique per base type; Integer and Enumeration share one.
BASE_TYPE = dict(Real='Real', Integer='Integer', Enumeration='Integer', Boolean='Boolean', String='String')

# 2.2.7, tables of causality/variability: the allowed combinations, each with its class
# (A)..(E) that gives the possible values of `initial` and the default one.
COMBINATION = {('parameter', 'fixed'): 'A', ('parameter', 'tunable'): 'A',
               ('calculatedParameter', 'fixed'): 'B', ('calculatedParameter', 'tunable'): 'B',
               ('input', 'discrete'): 'D', ('input', 'continuous'): 'D',
               ('output', 'constant'): 'A', ('output', 'discrete'): 'C', ('output', 'continuous'): 'C',
               ('local', 'constant'): 'A', ('local', 'fixed'): 'B', ('local', 'tunable'): 'B',
               ('local', 'discrete'): 'C', ('local', 'continuous'): 'C',
               ('independent', 'continuous'): 'E'}
INITIAL = dict(A=('exact', ('exact',)), B=('calculated', ('approx', 'calculated')),
               C=('calculated', ('exact', 'approx', 'calculated')), D=(None, ()), E=(None, ()))


class Var:
    """One ScalarVariable, with the defaults of the standard applied."""
    def __init__(self, index, el):
        self.index, self.el = index, el
        self.name = el.get('name')
        self.where = f'variable "{self.name}"' if self.name is not None else f'ModelVariables/ScalarVariable[{index}]'
        self.causality = el.get('causality', 'local').strip()        # 2.2.7: default local
        self.variability = el.get('variability', 'continuous').strip()  # 2.2.7: default continuous
        self.initial = el.get('initial')
        self.type = None  # Real, Integer, Boolean, String or Enumeration
        self.start = self.unit = self.derivative = None


class Checker:
    def __init__(self):
        self.errors = []

    def err(self, where, rule):
        self.errors.append(f'{where}: {rule}')

    # --- generic structure -----------------------------------------------------------
    def attrs(self, el, where, spec, required=()):
        for a, v in el.attrib.items():
            if a.startswith(XSI):
                continue
            if a not in spec:
                self.err(where, f'attribute {a} is not allowed here')
            elif not spec[a](v):
                self.err(where, f'attribute {a}="{v}" must be {spec[a].what}')
        for a in required:
            if a not in el.attrib:
                self.err(where, f'required attribute {a} is missing')

    def seq(self, el, where, order, required=(), repeat=()):
        """Children only from `order` (tuples hold elements of the same rank), in that order,
        each at most once unless in `repeat`; returns the first child of each name."""
        rank = {n: i for i, t in enumerate(order) for n in (t if isinstance(t, tuple) else (t,))}
        found, last = {}, -1
        for c in el:
            if c.tag not in rank:
                self.err(where, f'element {c.tag} is not allowed here')
            elif c.tag in found and c.tag not in repeat:
                self.err(where, f'element {c.tag} may appear only once')
            else:
                if rank[c.tag] < last:
                    self.err(where, f'element {c.tag} is out of order (the order is '
                                    f'{", ".join("/".join(t) if isinstance(t, tuple) else t for t in order)})')
                found.setdefault(c.tag, c)
                last = max(last, rank[c.tag])
        for t in required:
            if t not in found:
                self.err(where, f'required element {t} is missing')
        return found

    def items(self, el, where, tag):
        """2.2.1: an optional element that is a list must hold at least one item."""
        out = [c for c in el if c.tag == tag]
        self.seq(el, where, [tag], repeat=(tag,))
        if not out:
            self.err(where, f'the list must have at least one {tag} element')
        return out

    def leaf(self, el, where, spec, required=()):
        self.attrs(el, where, spec, required)
        self.seq(el, where, [])

    def unique_names(self, els, where, what):
        seen = set()
        for i, e in enumerate(els, 1):
            n = e.get('name')
            if n is not None and n in seen:
                self.err(f'{where}[{i}]', f'{what} name "{n}" is not unique')
            seen.add(n)
        return seen

    # --- 2.2.1 fmiModelDescription ---------------------------------------------------------
    def check(self, root):
        if root.tag != 'fmiModelDescription':
            self.err(root.tag, 'the root element must be fmiModelDescription')
            return []
        w = 'fmiModelDescription'
        self.attrs(root, w, ROOT_ATTRS, ('fmiVersion', 'modelName', 'guid'))
        if root.get('fmiVersion', '2.0') != '2.0':
            self.err(w, f'fmiVersion="{root.get("fmiVersion")}" must be "2.0"')
        top = self.seq(root, w, ROOT_CHILDREN, required=('ModelVariables', 'ModelStructure'))
        if 'ModelExchange' not in top and 'CoSimulation' not in top:
            self.err(w, 'at least one of ModelExchange and CoSimulation must be present')
        for kind, spec in (('ModelExchange', ME_ATTRS), ('CoSimulation', CS_ATTRS)):
            if kind in top:
                self.fmu_kind(top[kind], kind, spec)
        units = self.unit_definitions(top.get('UnitDefinitions'))
        types = self.type_definitions(top.get('TypeDefinitions'), units)
        if 'LogCategories' in top:  # 2.2.4
            cats = self.items(top['LogCategories'], 'LogCategories', 'Category')
            for i, c in enumerate(cats, 1):
                self.leaf(c, f'LogCategories/Category[{i}]', dict(name=STR, description=STR), ('name',))
            self.unique_names(cats, 'LogCategories/Category', 'category')
        if 'DefaultExperiment' in top:  # 2.2.5
            self.leaf(top['DefaultExperiment'], 'DefaultExperiment',
                      dict(startTime=DOUBLE, stopTime=DOUBLE, tolerance=DOUBLE, stepSize=DOUBLE))
        if 'VendorAnnotations' in top:  # 2.2.6
            self.annotations(top['VendorAnnotations'], 'VendorAnnotations')
        vs = self.variables(top.get('ModelVariables'), units, types, root, 'ModelExchange' in top)
        for n in types:  # 2.2.3: type names differ from variable names
            if any(v.name == n for v in vs):
                self.err(f'TypeDefinitions/SimpleType "{n}"', 'a type must not have the name of a variable')
        if 'ModelStructure' in top:
            self.model_structure(top['ModelStructure'], vs)
        return vs

    # 3.3.1 ModelExchange, 4.3.1 CoSimulation
    def fmu_kind(self, el, w, spec):
        self.attrs(el, w, spec, ('modelIdentifier',))
        if 'SourceFiles' in self.seq(el, w, ['SourceFiles']):
            for i, f in enumerate(self.items(el.find('SourceFiles'), f'{w}/SourceFiles', 'File'), 1):
                self.leaf(f, f'{w}/SourceFiles/File[{i}]', dict(name=STR), ('name',))
        # 4.3.1: an FMU that can serialize its state must be able to get and set it.
        if el.get('canSerializeFMUstate', '').strip() in ('true', '1') and \
                el.get('canGetAndSetFMUstate', '').strip() not in ('true', '1'):
            self.err(w, 'canSerializeFMUstate="true" requires canGetAndSetFMUstate="true"')

    # fmi2Annotation (2.2.6, 2.2.7): a list of Tool elements with unique names, any content.
    def annotations(self, el, w):
        tools = self.items(el, w, 'Tool')
        for i, t in enumerate(tools, 1):
            self.attrs(t, f'{w}/Tool[{i}]', dict(name=STR), ('name',))
        self.unique_names(tools, f'{w}/Tool', 'tool')

    # 2.2.2 UnitDefinitions: returns {unit name: set of display unit names}
    def unit_definitions(self, el):
        units = {}
        if el is None:
            return units
        num = dict(factor=DOUBLE, offset=DOUBLE)
        for i, u in enumerate(self.items(el, 'UnitDefinitions', 'Unit'), 1):
            w = f'UnitDefinitions/Unit[{i}]'
            self.attrs(u, w, dict(name=STR), ('name',))
            parts = self.seq(u, w, ['BaseUnit', 'DisplayUnit'], repeat=('DisplayUnit',))
            if 'BaseUnit' in parts:
                exps = {e: INT for e in ('kg', 'm', 's', 'A', 'K', 'mol', 'cd', 'rad')}
                self.leaf(parts['BaseUnit'], f'{w}/BaseUnit', dict(exps, **num))
            displays = u.findall('DisplayUnit')
            for j, d in enumerate(displays, 1):
                self.leaf(d, f'{w}/DisplayUnit[{j}]', dict(name=STR, **num), ('name',))
            names = self.unique_names(displays, f'{w}/DisplayUnit', 'display unit')
            if u.get('name') in units:
                self.err(w, f'unit name "{u.get("name")}" is not unique')
            units[u.get('name')] = names
        return units

    # 2.2.3 TypeDefinitions: returns {type name: (kind, element)}
    def type_definitions(self, el, units):
        types = {}
        if el is None:
            return types
        for i, st in enumerate(self.items(el, 'TypeDefinitions', 'SimpleType'), 1):
            n = st.get('name')
            w = f'TypeDefinitions/SimpleType "{n}"' if n is not None else f'TypeDefinitions/SimpleType[{i}]'
            self.attrs(st, w, dict(name=STR, description=STR), ('name',))
            kinds = [c for c in st if c.tag in TYPES]
            self.seq(st, w, [TYPES])
            if len(kinds) != 1:
                self.err(w, 'exactly one of Real, Integer, Boolean, String, Enumeration is required')
                continue
            t = kinds[0]
            self.attrs(t, f'{w}/{t.tag}', SIMPLE_TYPE_ATTRS[t.tag])
            if t.tag == 'Enumeration':
                items = self.items(t, f'{w}/Enumeration', 'Item')
                values = []
                for j, it in enumerate(items, 1):
                    self.leaf(it, f'{w}/Enumeration/Item[{j}]', dict(name=STR, value=INT, description=STR),
                              ('name', 'value'))
                    if it.get('value') in values:
                        self.err(f'{w}/Enumeration/Item[{j}]', f'item value {it.get("value")} is not unique')
                    values.append(it.get('value'))
            else:
                self.seq(t, f'{w}/{t.tag}', [])
            self.units_of(t, f'{w}/{t.tag}', t.get('unit'), units)
            self.ranges(t, f'{w}/{t.tag}', lambda a: t.get(a))
            if n in types:
                self.err(w, f'type name "{n}" is not unique')
            types[n] = (t.tag, t)
        return types

    def units_of(self, t, w, unit, units):
        """2.2.3: a unit must be defined in UnitDefinitions; displayUnit needs a (defined) unit."""
        if t.get('unit') is not None and t.get('unit') not in units:
            self.err(w, f'unit "{t.get("unit")}" is not defined in UnitDefinitions')
        if t.get('displayUnit') is not None and (unit is None or unit not in units):
            self.err(w, 'displayUnit requires a unit defined in UnitDefinitions')

    def ranges(self, t, w, get):
        """2.2.3 / 2.2.7: max >= min, min <= start <= max, nominal > 0."""
        num = DOUBLE if t.tag == 'Real' else INT
        val = {a: float(get(a)) for a in ('min', 'max', 'start', 'nominal')
               if get(a) is not None and num(get(a))}
        if 'min' in val and 'max' in val and val['max'] < val['min']:
            self.err(w, f'max={get("max")} is less than min={get("min")}')
        if 'start' in val and not val.get('min', val['start']) <= val['start'] <= val.get('max', val['start']):
            self.err(w, f'start={get("start")} is outside min..max')
        if 'nominal' in val and t.tag == 'Real' and val['nominal'] <= 0:
            self.err(w, 'nominal must be > 0')

    # --- 2.2.7 ModelVariables ---------------------------------------------------------------
    def variables(self, el, units, types, root, has_me):
        if el is None:
            return []
        vs = [Var(i, sv) for i, sv in enumerate(self.items(el, 'ModelVariables', 'ScalarVariable'), 1)]
        convention = root.get('variableNamingConvention', 'flat').strip()
        by_name = {}
        for v in vs:
            self.variable(v, units, types, has_me)
            if v.name is None:
                continue
            if v.name in by_name:
                self.err(v.where, f'the name is not unique (also variable {by_name[v.name]})')
            by_name.setdefault(v.name, v.index)
            # 2.2.9: names are non-empty; flat names have no CR, LF or TAB; structured names
            # follow the grammar given there.
            if v.name == '' or (convention == 'flat' and re.search('[\r\n\t]', v.name)):
                self.err(v.where, 'the name is not a valid flat name')
            elif convention == 'structured' and not STRUCTURED_NAME.fullmatch(v.name):
                self.err(v.where, 'the name is not a valid structured name')
        independents = [v for v in vs if v.causality == 'independent']
        if len(independents) > 1:
            self.err(independents[1].where, 'at most one variable may have causality="independent"')
        for v in vs:  # "derivative" is the index of the variable this one is the derivative of
            if v.derivative is not None and UINT(v.derivative):
                d = int(v.derivative)
                if not 1 <= d <= len(vs):
                    self.err(v.where, f'derivative={d} is not a variable index (1..{len(vs)})')
                elif vs[d - 1].type != 'Real':
                    self.err(v.where, f'derivative={d} must refer to a Real variable')
        self.aliases(vs)
        return vs

    def variable(self, v, units, types, has_me):
        w = v.where
        self.attrs(v.el, w, VAR_ATTRS, ('name', 'valueReference'))
        kinds = [c for c in v.el if c.tag in TYPES]
        self.seq(v.el, w, [TYPES, 'Annotations'])
        if v.el.find('Annotations') is not None:
            self.annotations(v.el.find('Annotations'), f'{w}/Annotations')
        if len(kinds) != 1:
            self.err(w, 'exactly one type element (Real, Integer, Boolean, String, Enumeration) is required')
            return
        t = kinds[0]
        v.type, v.start, v.derivative = t.tag, t.get('start'), t.get('derivative')
        self.attrs(t, f'{w}/{t.tag}', VAR_TYPE_ATTRS[t.tag], ('declaredType',) if t.tag == 'Enumeration' else ())
        self.seq(t, f'{w}/{t.tag}', [])
        # 2.2.7: declaredType names a SimpleType of the same kind, whose attributes are defaults.
        dt = t.get('declaredType')
        default = None
        if dt is not None:
            if dt not in types:
                self.err(w, f'declaredType "{dt}" is not defined in TypeDefinitions')
            elif types[dt][0] != t.tag:
                self.err(w, f'declaredType "{dt}" is a {types[dt][0]} type, not {t.tag}')
            else:
                default = types[dt][1]

        def get(a):
            return t.get(a, default.get(a) if default is not None else None)
        v.unit = get('unit')
        self.units_of(t, w, v.unit, units)
        self.ranges(t, w, get)
        # 2.2.7, variability: only Real variables can be continuous.
        if v.variability == 'continuous' and t.tag != 'Real':
            self.err(w, f'variability="continuous" is only allowed for Real, not {t.tag}')
        if v.causality not in CAUSALITIES or v.variability not in VARIABILITIES:
            return  # already reported by attrs()
        # 2.2.7, table of the allowed causality/variability combinations.
        cls = COMBINATION.get((v.causality, v.variability))
        if cls is None:
            self.err(w, f'causality="{v.causality}" with variability="{v.variability}" is not allowed')
            return
        # 2.2.7, initial: not for inputs and the independent variable; else from the table.
        # (A wrong initial is reported and replaced by the default for the checks below.)
        default_initial, possible = INITIAL[cls]
        given, v.initial = (v.initial or '').strip(), default_initial
        if given and v.causality in ('input', 'independent'):
            self.err(w, f'initial is not allowed with causality="{v.causality}"')
        elif given in ('exact', 'approx', 'calculated') and given not in possible:
            self.err(w, f'initial="{given}" is not allowed with causality="{v.causality}" and '
                        f'variability="{v.variability}" (allowed: {", ".join(possible)})')
        elif given in possible:
            v.initial = given
        # 2.2.7, start: required with initial exact/approx or an input (constants are exact),
        # not allowed with initial calculated or for the independent variable.
        if v.start is None and (v.initial in ('exact', 'approx') or v.causality == 'input'):
            why = f'causality="input"' if v.causality == 'input' else f'initial="{v.initial}"'
            self.err(w, f'a start value is required ({why})')
        if v.start is not None and (v.initial == 'calculated' or v.causality == 'independent'):
            why = f'initial="calculated"' if v.initial == 'calculated' else 'causality="independent"'
            self.err(w, f'a start value is not allowed with {why}')
        # 2.2.7, causality independent: the variable must be a Real.
        if v.causality == 'independent' and t.tag != 'Real':
            self.err(w, 'the independent variable must be a Real')
        # 2.2.7: canHandleMultipleSetPerTimeInstant is only for ModelExchange.
        if 'canHandleMultipleSetPerTimeInstant' in v.el.attrib and not has_me:
            self.err(w, 'canHandleMultipleSetPerTimeInstant is only allowed for ModelExchange')

    def aliases(self, vs):
        """2.2.7: variables of one base type with the same valueReference are aliases, with
        the standard's restrictions: (1) at most one of them can be set (and none if one is
        the independent variable), (2) at most one non-constant one has a start value, (3)
        constants only alias constants with the same start value, (4) they have one unit."""
        groups = {}
        for v in vs:
            if v.type and v.el.get('valueReference') is not None and UINT(v.el.get('valueReference')):
                groups.setdefault((BASE_TYPE[v.type], int(v.el.get('valueReference'))), []).append(v)
        for (base, vr), g in groups.items():
            if len(g) < 2:
                continue
            names = ', '.join(f'"{v.name}"' for v in g)
            w = f'valueReference {vr} ({base})'
            settable = [v for v in g if v.variability != 'constant' and
                        (v.causality in ('parameter', 'input') or v.initial in ('exact', 'approx'))]
            if len(settable) > 1 or (settable and any(v.causality == 'independent' for v in g)):
                self.err(w, f'shared by {names}: aliases must not be set independently')
            if len([v for v in g if v.variability != 'constant' and v.start is not None]) > 1:
                self.err(w, f'shared by {names}: at most one non-constant alias may have a start value')
            constants = [v for v in g if v.variability == 'constant']
            if constants and len(constants) < len(g):
                self.err(w, f'shared by {names}: a constant can only be an alias of constants')
            elif len({v.start for v in constants}) > 1:
                self.err(w, f'shared by {names}: aliased constants need the same start value')
            if len({v.unit for v in g}) > 1:
                self.err(w, f'shared by {names}: aliases must have the same unit')

    # --- 2.2.8 ModelStructure ---------------------------------------------------------------
    def model_structure(self, el, vs):
        lists = self.seq(el, 'ModelStructure', ['Outputs', 'Derivatives', 'InitialUnknowns'])
        parsed = {k: self.unknowns(lists[k], f'ModelStructure/{k}', vs, k == 'InitialUnknowns')
                  for k in lists}
        outs, ders, inits = (parsed.get(k, []) for k in ('Outputs', 'Derivatives', 'InitialUnknowns'))
        # Outputs: exactly the variables with causality="output", each once.
        for w, i, _ in outs:
            if vs[i - 1].causality != 'output':
                self.err(w, f'{vs[i - 1].where} is not an output')
        listed = [i for _, i, _ in outs]
        for w, i, _ in outs:
            if listed.count(i) > 1:
                self.err(w, f'{vs[i - 1].where} is listed more than once')
        for v in vs:
            if v.causality == 'output' and v.index not in listed:
                self.err(v.where, 'an output must be listed in ModelStructure/Outputs')
        # Derivatives: state derivatives, Real variables with the attribute derivative.
        states = set()
        for w, i, _ in ders:
            v = vs[i - 1]
            if v.type != 'Real' or v.derivative is None:
                self.err(w, f'{v.where} is not a state derivative (a Real with attribute derivative)')
            elif UINT(v.derivative) and 1 <= int(v.derivative) <= len(vs):
                states.add(int(v.derivative))
        # Knowns that the dependencies may name: inputs, continuous-time states and the
        # independent variable; in Initialization Mode inputs, initial="exact" and independent.
        for name, items in (('Outputs', outs), ('Derivatives', ders), ('InitialUnknowns', inits)):
            for w, i, deps in items:
                for d in deps:
                    k = vs[d - 1]
                    known = k.causality in ('input', 'independent') or (
                        k.initial == 'exact' if name == 'InitialUnknowns' else d in states)
                    if not known:
                        self.err(w, f'dependency {d} ({k.where}) is not a known of {name}')
        # InitialUnknowns: outputs with initial approx/calculated, calculated parameters and
        # (only where Derivatives are given, 4.3: a co-simulation FMU need not) the states and
        # state derivatives with initial approx/calculated; no others, ascending, no duplicates.
        expected = {v.index for v in vs if
                    (v.causality == 'output' and v.initial in ('approx', 'calculated')) or
                    v.causality == 'calculatedParameter' or
                    ((v.index in states or v.index in {i for _, i, _ in ders}) and
                     v.initial in ('approx', 'calculated'))}
        got = [i for _, i, _ in inits]
        for (w, i, _), prev in zip(inits[1:], got):
            if i <= prev:
                self.err(w, 'InitialUnknowns must be in ascending index order without duplicates')
        for w, i, _ in inits:
            if i not in expected:
                self.err(w, f'{vs[i - 1].where} does not belong in InitialUnknowns')
        for i in sorted(expected - set(got)):
            v = vs[i - 1]
            self.err(v.where, f'must be listed in ModelStructure/InitialUnknowns '
                              f'(causality="{v.causality}", initial="{v.initial}")')

    def unknowns(self, el, where, vs, initial):
        """Unknown elements: index (1-based into ModelVariables), dependencies (ascending valid
        indices), dependenciesKind (same length; in InitialUnknowns only dependent/constant;
        other than dependent only for Real unknowns). Returns (where, index, deps) of valid ones."""
        out = []
        n = len(vs)
        for j, u in enumerate(self.items(el, where, 'Unknown'), 1):
            w = f'{where}/Unknown[{j}]'
            self.leaf(u, w, dict(index=UINT, dependencies=UINT_LIST, dependenciesKind=KIND_LIST), ('index',))
            if not UINT(u.get('index', '')):
                continue
            i = int(u.get('index'))
            if not 1 <= i <= n:
                self.err(w, f'index {i} is out of range (1..{n})')
                continue
            deps = [int(d) for d in u.get('dependencies', '').split()] if UINT_LIST(u.get('dependencies', '')) else []
            for d in deps:
                if not 1 <= d <= n:
                    self.err(w, f'dependency {d} is out of range (1..{n})')
            deps = [d for d in deps if 1 <= d <= n]
            if deps != sorted(set(deps)):
                self.err(w, 'dependencies must be in ascending order without duplicates')
            kinds = u.get('dependenciesKind')
            if kinds is not None:
                kinds = kinds.split()
                if u.get('dependencies') is None or len(kinds) != len(u.get('dependencies').split()):
                    self.err(w, 'dependenciesKind needs dependencies with the same number of entries')
                if initial and any(k in ('fixed', 'tunable', 'discrete') for k in kinds):
                    self.err(w, 'dependenciesKind in InitialUnknowns can only be dependent or constant')
                if vs[i - 1].type != 'Real' and any(k != 'dependent' for k in kinds):
                    self.err(w, 'dependenciesKind other than dependent is only for Real unknowns')
            out.append((w, i, deps))
        return out


def main(argv):
    if len(argv) < 2 or argv[1] in ('-h', '--help'):
        print(__doc__.strip().splitlines()[2], file=sys.stdout if len(argv) > 1 else sys.stderr)
        return 0 if len(argv) > 1 else 2
    status = 0
    for path in argv[1:]:
        try:
            root = ET.parse(path).getroot()
        except OSError as e:
            print(f'{path}: cannot read: {e.strerror or e}', file=sys.stderr)
            status = 2
            continue
        except ET.ParseError as e:
            print(f'{path}: not XML: {e}', file=sys.stderr)
            status = 2
            continue
        c = Checker()
        vs = c.check(root)
        for e in c.errors:
            print(f'{path}: {e}')
        if c.errors:
            status = max(status, 1)
        else:
            print(f'{path}: ok ({len(vs)} variables)')
    return status


if __name__ == '__main__':
    sys.exit(main(sys.argv))
