#!/usr/bin/env python3
"""The layout's rules, checked against the code (docs/layout.md says them; this holds them):

1. The core's rooms (include/dem_mobility/core/ROOM, src/core/ROOM) stand in the order of
   docs/layout.md's room table; a room includes only itself and the rooms above it. The core
   includes nothing of the ROS layer (dem_mobility/ros, ros/, any message header).
2. No file of the core includes itself back through others (no cycle of includes).
3. No source file (the library, the nodelets, the tools, the benchmarks, the Python package, the
   tests) is longer than MAX_FILE_LINES lines, and no function longer than MAX_FUNCTION_LINES,
   except the ones named in EXCEPTIONS with their reason.

Usage: check_layout.py REPO     (exit 1 naming every breach)
       check_layout.py --self-test  (breaches planted in a copy must be found)
"""
import ast
import os
import re
import shutil
import subprocess
import sys
import tempfile

MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 100
# Functions allowed past MAX_FUNCTION_LINES, each with its reason.
EXCEPTIONS = {
    'src/core/dem/neighbour_list.cpp:ListPairs':
        'a DEM hot loop: the cell walk appends pairs without a branch; split, its state would pass through calls',
    'src/core/dem/wall_contacts.cpp:ComputeSlot':
        'a DEM hot loop: one slot against every wall with candidates, run for every particle every step',
}

INCLUDE = re.compile(r'^\s*#\s*include\s+["<]([^">]+)[">]', re.M)
# what the core may not include: the ROS layer, ROS itself, messages, the tools
ROS_INCLUDE = re.compile(r'^(ros/|nodelet/|pluginlib/|rosbag/|tf2[a-z_]*/|[a-z_]+_msgs/|dem_mobility/(?!core/))')
CORE_INCLUDE = re.compile(r'^dem_mobility/core/([a-z_]+)/([A-Za-z0-9_.]+)$')


def room_order(repo):
    """The rooms in docs/layout.md's table, top first."""
    text = open(os.path.join(repo, 'docs', 'layout.md'), encoding='utf-8').read()
    rooms = re.findall(r'^\| `([a-z_]+)/` \|', text, re.M)
    if not rooms:
        raise SystemExit('docs/layout.md: no room table (rows "| `room/` | ... |") found')
    return rooms


def core_files(repo):
    """(room, path relative to repo) of every header and source of the core."""
    out = []
    for base in ('include/dem_mobility/core', 'src/core'):
        top = os.path.join(repo, base)
        for room in sorted(os.listdir(top)):
            d = os.path.join(top, room)
            if not os.path.isdir(d):
                continue
            for dirpath, _, files in os.walk(d):
                for f in sorted(files):
                    if f.endswith(('.h', '.cpp')):
                        out.append((room, os.path.relpath(os.path.join(dirpath, f), repo)))
    return out


def check_rooms(repo):
    order = room_order(repo)
    breaches = []
    graph = {}
    for room, path in core_files(repo):
        if room not in order:
            breaches.append(f'{path}: room {room}/ is not in docs/layout.md\'s room table')
            continue
        text = open(os.path.join(repo, path), encoding='utf-8').read()
        node = path_key(path)
        graph.setdefault(node, set())
        for inc in INCLUDE.findall(text):
            m = CORE_INCLUDE.match(inc)
            if ROS_INCLUDE.match(inc):
                breaches.append(f'{path}: includes {inc}: the core includes nothing of ROS, the ROS layer or the tools')
                continue
            if inc.startswith('dem_mobility/core/') and not m:
                breaches.append(f'{path}: includes {inc}: not a header of a room (dem_mobility/core/ROOM/FILE)')
                continue
            if not m:
                continue
            other = m.group(1)
            graph[node].add(f'{other}/{os.path.splitext(m.group(2))[0]}')
            if other not in order:
                breaches.append(f'{path}: includes {inc}: room {other}/ is not in docs/layout.md')
            elif order.index(other) > order.index(room):
                breaches.append(f'{path}: includes {inc}: room {other}/ stands below {room}/ in docs/layout.md')
    breaches += [f'include cycle: {" -> ".join(c)}' for c in cycles(graph)]
    return breaches


def path_key(path):
    """include/dem_mobility/core/soil/x.h and src/core/soil/x.cpp are one unit, soil/x: a cycle is
    one between units (a header and its source together), stricter than one between files."""
    parts = path.split('/')
    room = parts[3] if parts[0] == 'include' else parts[2]
    return f'{room}/{os.path.splitext(parts[-1])[0]}'


def cycles(graph):
    """The strongly connected components of more than one unit (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in graph:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


SOURCE_FOLDERS = ('include', 'src', 'bench', 'python', 'test', 'scripts')


def sources(repo, suffixes):
    for base in SOURCE_FOLDERS:
        for dirpath, _, files in os.walk(os.path.join(repo, base)):
            for f in sorted(files):
                if f.endswith(suffixes):
                    yield os.path.relpath(os.path.join(dirpath, f), repo)


def cpp_functions(repo, paths):
    """(path, name, first line, length) of every C++ function (universal-ctags)."""
    out = subprocess.run(['ctags-universal', '-x', '--_xformat=%N\t%F\t%n\t%{end}', '--kinds-C++=f', '--fields=+ne',
                          '--language-force=C++', *paths], cwd=repo, capture_output=True, text=True, check=True).stdout
    for line in out.splitlines():
        name, path, start, end = line.split('\t')
        if not end.isdigit():
            raise SystemExit(f'{path}:{start}: ctags gives {name} no end line: its length cannot be checked')
        yield path, name, int(start), int(end) - int(start) + 1


def python_functions(repo, paths):
    """(path, name, first line, length) of every Python function (ast)."""
    for path in paths:
        with open(os.path.join(repo, path), encoding='utf-8') as f:
            tree = ast.parse(f.read(), path)
        for n in ast.walk(tree):
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)):
                yield path, n.name, n.lineno, n.end_lineno - n.lineno + 1


def check_sizes(repo):
    breaches = []
    cpp = list(sources(repo, ('.h', '.cpp')))
    py = list(sources(repo, ('.py',)))
    for path in cpp + py:
        n = sum(1 for _ in open(os.path.join(repo, path), encoding='utf-8'))
        if n > MAX_FILE_LINES:
            breaches.append(f'{path}: {n} lines (at most {MAX_FILE_LINES})')
    for path, name, start, length in list(cpp_functions(repo, cpp)) + list(python_functions(repo, py)):
        if length > MAX_FUNCTION_LINES and f'{path}:{name}' not in EXCEPTIONS:
            breaches.append(f'{path}:{start}: {name} is {length} lines (at most {MAX_FUNCTION_LINES})')
    return breaches


def check(repo):
    return check_rooms(repo) + check_sizes(repo)


def self_test():
    """Plants one breach of each rule in a copy of the checkout; each must be found."""
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        copy = os.path.join(tmp, 'repo')
        for d in SOURCE_FOLDERS + ('docs',):
            if os.path.isdir(os.path.join(repo, d)):
                shutil.copytree(os.path.join(repo, d), os.path.join(copy, d),
                                ignore=shutil.ignore_patterns('__pycache__'))
        clean = '\n'.join(check(copy))
        order = room_order(copy)
        top, bottom = order[0], order[-1]
        planted = os.path.join(copy, 'include', 'dem_mobility', 'core', top, 'planted.h')
        with open(planted, 'w') as f:
            f.write(f'#pragma once\n#include "dem_mobility/core/{bottom}/planted_low.h"\n')
        low = os.path.join(copy, 'include', 'dem_mobility', 'core', bottom, 'planted_low.h')
        with open(low, 'w') as f:
            f.write(f'#pragma once\n#include "dem_mobility/core/{top}/planted.h"\n#include <ros/ros.h>\n')
        long_fn = os.path.join(copy, 'src', 'core', top, 'planted_long.cpp')
        with open(long_fn, 'w') as f:
            f.write('int Planted() {\n' + '  int a = 0;\n' * MAX_FUNCTION_LINES + '  return a;\n}\n')
        with open(os.path.join(copy, 'python', 'planted_long.py'), 'w') as f:
            f.write('def planted_py():\n' + '    a = 0\n' * MAX_FUNCTION_LINES + '    return a\n')
        long_file = os.path.join(copy, 'src', 'core', top, 'planted_file.cpp')
        with open(long_file, 'w') as f:
            f.write('// line\n' * (MAX_FILE_LINES + 1))
        found = '\n'.join(check(copy))
        for what, needle in (('an include against the order', f'room {bottom}/ stands below {top}/'),
                             ('a cycle', 'include cycle:'),
                             ('a ROS include in the core', 'includes ros/ros.h: the core includes nothing of ROS'),
                             ('a long function', 'Planted is'),
                             ('a long Python function', 'planted_py is'),
                             ('a long file', 'planted_file.cpp: ')):
            if needle in clean:
                failures.append(f'{what}: "{needle}" is reported before anything is planted')
            elif needle not in found:
                failures.append(f'{what} was not found')
    for f in failures:
        print('self-test:', f)
    return 1 if failures else 0


def main(argv):
    if argv[1:] == ['--self-test']:
        return self_test()
    if len(argv) != 2:
        print(__doc__)
        return 2
    breaches = check(argv[1])
    for b in breaches:
        print(b)
    print(f'layout: {len(breaches)} breaches')
    return 1 if breaches else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
