#!/usr/bin/env python3
"""Checks of the repository as a whole, run by CTest (tests/architecture/CMakeLists.txt).

  check_repository.py layers ROOT       every #include of an Impetus header respects the layers declared in
                                        docs/architecture.md ("Layers" table): a file includes headers of its
                                        own layer and of the layers it lists, never of a layer above it
  check_repository.py standalone ROOT   no file points outside the repository (to the developers' shared
                                        folder beside it), and every relative Markdown link resolves inside it
  check_repository.py libraries ROOT LIBDIR
                                        the built libraries link as the layers say (readelf -d): a layer's
                                        libimpetus_<layer>.so needs only the libraries of the layers it may
                                        include, a plugin needs no Impetus library, and yaml-cpp, assimp and
                                        FCL are linked only by the engine, the assets and the fcl plugin

Each failure is printed as FILE:LINE: problem; the exit status is 1 when there is any.
"""
import os
import re
import subprocess
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"](impetus/[^>"]+)[>"]')
# A quoted include with a folder that is not impetus/…: ambiguous (which `common/`?) and shadowing
# (a plugin folder on the include path hides a library's own folder of the same name).
QUOTED_PATH = re.compile(r'^\s*#\s*include\s*"((?!impetus/)[^"]*/[^"]*)"')
SOURCE_SUFFIXES = ('.cpp', '.hpp', '.h', '.cc')
# Parts of the repository that use the engine from the outside: they may include any layer.
CLIENTS = ('tests/', 'benchmarks/', 'fuzz/', 'examples/')


def repository_files(root):
    """The repository's own files: git's list when this is a checkout, else a walk without build trees."""
    try:
        out = subprocess.run(['git', '-C', root, 'ls-files', '-z'], check=True, capture_output=True).stdout
        files = [f for f in out.decode().split('\0') if f]
        if files:
            return [f for f in files if os.path.isfile(os.path.join(root, f))]
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for top, dirs, names in os.walk(root):
        dirs[:] = [d for d in dirs if not d.startswith(('.', 'build'))]
        files += [os.path.relpath(os.path.join(top, n), root) for n in names]
    return files


def read_layers(root):
    """The "Layers" table of docs/architecture.md: name -> (folders, header prefixes, layers it may include)."""
    path = os.path.join(root, 'docs', 'architecture.md')
    layers, in_table = {}, False
    with open(path, encoding='utf-8') as f:
        for line in f:
            if line.startswith('## '):
                in_table = line.strip() == '## Layers'
                continue
            if not in_table or not line.startswith('|') or set(line.strip()) <= set('|- '):
                continue
            cells = [c.strip() for c in line.strip().strip('|').split('|')]
            if len(cells) != 5 or cells[0] == 'layer':
                continue
            name = cells[0].strip('*')
            ticks = lambda cell: re.findall(r'`([^`]+)`', cell)
            allowed = [a.strip() for a in cells[4].split(',') if a.strip() not in ('', '—')]
            layers[name] = (ticks(cells[2]), ticks(cells[3]), allowed)
    if not layers:
        sys.exit(f'{path}: no "Layers" table found')
    for name, (_, _, allowed) in layers.items():
        for other in allowed:
            if other not in layers:
                sys.exit(f'{path}: layer {name} may include "{other}", which is not a layer')
    return layers


def longest_match(path, prefixes_by_layer):
    best, best_len = None, -1
    for name, prefixes in prefixes_by_layer.items():
        for prefix in prefixes:
            if (path == prefix or path.startswith(prefix.rstrip('/') + '/') or path.startswith(prefix)) \
                    and len(prefix) > best_len:
                best, best_len = name, len(prefix)
    return best


def plugin_scope(rel):
    """For a file of a plugin area (integrators/X/…, detection/X/…, resolution/X/…): (area, X)."""
    parts = rel.split('/')
    if parts[0] in ('integrators', 'detection', 'resolution') and len(parts) > 2:
        return parts[0], parts[1]
    return None


def check_layers(root):
    layers = read_layers(root)
    folders = {name: spec[0] for name, spec in layers.items()}
    headers = {name: spec[1] for name, spec in layers.items()}
    failures = []
    for rel in repository_files(root):
        if not rel.endswith(SOURCE_SUFFIXES) or rel.startswith(CLIENTS):
            continue
        own = longest_match(rel, folders)
        if own is None:
            failures.append(f'{rel}:1: in no layer of docs/architecture.md ("Layers")')
            continue
        allowed = set(layers[own][2]) | {own}
        with open(os.path.join(root, rel), encoding='utf-8', errors='replace') as f:
            for number, line in enumerate(f, 1):
                local = QUOTED_PATH.match(line)
                if local:
                    failures.append(f'{rel}:{number}: "{local.group(1)}": include project headers as '
                                    f'"impetus/…" (a private header beside the source by its file name)')
                m = INCLUDE.match(line)
                if not m:
                    continue
                header = m.group(1)
                theirs = longest_match(header, headers)
                if theirs is None:
                    failures.append(f'{rel}:{number}: <{header}> belongs to no layer of docs/architecture.md')
                elif theirs not in allowed:
                    failures.append(f'{rel}:{number}: layer {own} includes <{header}> of layer {theirs} '
                                    f'(it may include: {", ".join(sorted(allowed))})')
                else:
                    # A plugin includes its own headers and its area's common library, never another plugin.
                    scope = plugin_scope(rel)
                    parts = header.split('/')
                    if scope and len(parts) > 3 and parts[1] == scope[0] and parts[2] not in (scope[1], 'common'):
                        failures.append(f'{rel}:{number}: plugin {scope[0]}/{scope[1]} includes <{header}> of '
                                        f'another plugin ({scope[0]}/{parts[2]})')
                    if scope and scope[1] == 'common' and len(parts) > 3 and parts[1] == scope[0] \
                            and parts[2] != 'common':
                        failures.append(f'{rel}:{number}: {scope[0]}/common includes the plugin header <{header}>')
    return failures


OUTSIDE = re.compile(r'\.\./' + 'shared' + r'|\bshared/(DESIGN|STYLE)\.md|\bshared/' + r'(papers|hooks)/'
                     + r'|\b' + 'DESIGN' + r'\.md\b|\b' + 'STYLE' + r'\.md\b')
LINK = re.compile(r'\]\(([^)\s]+)\)')


def check_standalone(root):
    failures = []
    this = os.path.relpath(os.path.abspath(__file__), root)
    for rel in repository_files(root):
        if rel == this:
            continue
        try:
            with open(os.path.join(root, rel), encoding='utf-8') as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue  # binary data (meshes, charts)
        for number, line in enumerate(text.splitlines(), 1):
            if OUTSIDE.search(line):
                failures.append(f'{rel}:{number}: points outside the repository: {line.strip()[:120]}')
            if rel.endswith('.md'):
                for target in LINK.findall(line):
                    if re.match(r'^[a-z]+:', target) or target.startswith('#'):
                        continue
                    path = os.path.normpath(os.path.join(os.path.dirname(rel), target.split('#')[0]))
                    if path.startswith('..') or not os.path.exists(os.path.join(root, path)):
                        failures.append(f'{rel}:{number}: link to {target}, which is not in the repository')
    return failures


# Third-party libraries that belong to one layer or plugin only (docs/architecture.md).
FOREIGN_OWNERS = {'libyaml-cpp': 'engine', 'libassimp': 'assets', 'libfcl': 'impetus_detector_fcl',
                  'libccd': 'impetus_detector_fcl'}


def needed(path):
    out = subprocess.run(['readelf', '-d', path], check=True, capture_output=True, text=True).stdout
    return re.findall(r'\(NEEDED\)\s+Shared library: \[([^\]]+)\]', out)


def check_libraries(root, libdir):
    layers = read_layers(root)
    failures, seen = [], 0
    plugin_dir = os.path.join(libdir, 'impetus', 'plugins')
    candidates = [(os.path.join(libdir, n), n[len('libimpetus_'):-len('.so')]) for n in sorted(os.listdir(libdir))
                  if n.startswith('libimpetus_') and n.endswith('.so')]
    if os.path.isdir(plugin_dir):
        candidates += [(os.path.join(plugin_dir, n), None) for n in sorted(os.listdir(plugin_dir)) if n.endswith('.so')]
    for path, layer in candidates:
        name = os.path.basename(path)
        if layer is not None and layer not in layers:
            failures.append(f'{path}: libimpetus_{layer}.so is no layer of docs/architecture.md')
            continue
        seen += 1
        allowed = set() if layer is None else set(layers[layer][2]) | {layer}
        owner = layer if layer is not None else name[:-len('.so')]
        for lib in needed(path):
            m = re.match(r'libimpetus_(\w+)\.so', lib)
            if m and m.group(1) not in allowed:
                what = 'a plugin' if layer is None else f'layer {layer}'
                failures.append(f'{path}: {what} links {lib} (layer {m.group(1)}), which it may not use')
            for prefix, lib_owner in FOREIGN_OWNERS.items():
                if lib.startswith(prefix) and owner != lib_owner:
                    failures.append(f'{path}: links {lib}, which only {lib_owner} may link')
    if seen < 4:
        failures.append(f'{libdir}: found {seen} Impetus libraries; expected the layers and the plugins')
    return failures


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else ''
    if (mode, len(sys.argv)) not in (('layers', 3), ('standalone', 3), ('libraries', 4)):
        sys.exit(__doc__)
    root = os.path.abspath(sys.argv[2])
    if mode == 'libraries':
        failures = check_libraries(root, sys.argv[3])
    else:
        failures = check_layers(root) if mode == 'layers' else check_standalone(root)
    for failure in failures:
        print(failure)
    print(f'{mode}: {len(failures)} problem(s)')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
