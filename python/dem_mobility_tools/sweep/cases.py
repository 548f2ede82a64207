"""The cases of a sweep: named parameters with a stable name (e.g. ``mu0.1_f2``), from the product of
named axes (`grid`) or from any list of parameter sets (`cases`, e.g. a design of experiments)."""
import itertools
import numbers
import re


def format_value(v):
    """A parameter value as it appears in a case name: numbers with %g (0.1, 2, 1e-05), the rest as
    text with anything but letters, digits, '.', '+' and '-' replaced by '-'."""
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, numbers.Real):
        return '%g' % v
    return re.sub(r'[^A-Za-z0-9.+-]', '-', str(v))


class Case:
    """One run of a sweep: its parameters (an ordered mapping axis -> value), its name (unique in
    the sweep, used for its files) and its index in the sweep. Parameters read as case['mu'] or
    case.mu."""

    def __init__(self, params, name=None, index=0):
        self.params = dict(params)
        self.name = name if name is not None else default_name(self.params)
        self.index = index
        if not self.name or '/' in self.name or self.name in ('.', '..'):
            raise ValueError('invalid case name %r' % self.name)

    def __getitem__(self, key):
        return self.params[key]

    def __getattr__(self, key):
        params = self.__dict__.get('params', {})
        if key in params:
            return params[key]
        raise AttributeError(key)

    def __repr__(self):
        return 'Case(%r, %r)' % (self.name, self.params)

    def __eq__(self, other):
        return isinstance(other, Case) and (self.name, self.params) == (other.name, other.params)

    def __hash__(self):
        return hash(self.name)


def default_name(params):
    """'mu0.1_f2' for {'mu': 0.1, 'f': 2}: each axis name followed by its value, in axis order."""
    return '_'.join('%s%s' % (k, format_value(v)) for k, v in params.items())


def _namer(name):
    if name is None:
        return default_name
    if callable(name):
        return name
    # a format string over the parameters: 'mu{mu:g}_f{f:g}'
    return lambda params: name.format(**params)


def cases(param_sets, name=None):
    """Cases from a list of parameter mappings (any design, not only a product), in that order.
    name: None (default_name), a format string over the parameters ('slip{slip:g}_{soil}') or a
    callable params -> name. Raises ValueError if two cases get the same name."""
    namer = _namer(name)
    out, seen = [], {}
    for k, p in enumerate(param_sets):
        c = Case(p, namer(dict(p)), k)
        if c.name in seen:
            raise ValueError('two cases named %r: %r and %r' % (c.name, seen[c.name], c.params))
        seen[c.name] = c.params
        out.append(c)
    return out


def grid(axes, name=None):
    """The product of named axes, the first axis outermost: axes is a mapping or a list of
    (name, values) pairs, e.g. [('mu', [0.1, 0.05]), ('f', [0.3, 5])] -> mu0.1_f0.3, mu0.1_f5,
    mu0.05_f0.3, mu0.05_f5. An axis with no value gives no case. name as in `cases`."""
    items = list(axes.items()) if hasattr(axes, 'items') else [tuple(a) for a in axes]
    keys = [k for k, _ in items]
    if len(set(keys)) != len(keys):
        raise ValueError('repeated axis in %r' % keys)
    values = [list(v) for _, v in items]
    return cases((dict(zip(keys, combo)) for combo in itertools.product(*values)), name)
