"""One name per thing: the keys the tools write for a grade, a cone index and a cohesion factor,
and the old names a file written before may hold, which the readers refuse naming the new one."""

GRADE = 'grade_deg'              # a grade [deg]
CONE_INDEX = 'cone_index_psi'    # a cone index [psi]
COHESION_FACTOR = 'cohesion_factor'  # the cohesion factor f

# an old key -> its one name
OLD = {'grade': GRADE, 'cone_index': CONE_INDEX, 'ci': CONE_INDEX, 'requested_ci': 'requested_' + CONE_INDEX,
       'ci_psi': CONE_INDEX, 'f': COHESION_FACTOR}


class OldNameError(ValueError):
    pass


def refuse_old_keys(mapping, path, where='', keys=('grade', 'cone_index', 'ci', 'requested_ci', 'ci_psi')):
    """OldNameError naming the file, the old key and its one name if `mapping` (a row or a result
    read from `path`; `where`: its place in the file, e.g. 'cases[3]') holds one of the old `keys`."""
    if not isinstance(mapping, dict):
        return
    for old in keys:
        if old in mapping:
            raise OldNameError('%s: %s%r is an old name: it is %r now (a file written by an older version of '
                               'the tools; rename the key or make the file again)'
                               % (path, where + ': ' if where else '', old, OLD[old]))
