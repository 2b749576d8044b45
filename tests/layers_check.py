#!/usr/bin/env python3
"""The layering check passes on this tree and fails on trees that break it.

usage: layers_check.py [BUILD]   (BUILD: this tree's CMake build, whose
objects the check reads; without it only the includes are checked)

Each case copies nothing: it writes a tiny tree (and, for the symbol rules,
compiles its .c files with $CC, default cc, into a build tree laid out as
CMake's) and runs scripts/check_layers.py on it, expecting the given exit
status."""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHECK = [sys.executable, os.path.join(ROOT, "scripts", "check_layers.py")]
BUILD = sys.argv.pop(1) if len(sys.argv) > 1 and not sys.argv[1].startswith("-") else None


def tree(files):
    d = tempfile.mkdtemp(prefix="hd-layers-")
    for rel, text in files.items():
        p = os.path.join(d, rel)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "w") as f:
            f.write(text)
    return d


def built(files):
    """A tree of files and its build: every .c compiled where CMake puts it."""
    d = tree(files)
    for rel in files:
        if rel.endswith(".c"):
            obj = os.path.join(d, "build", "CMakeFiles", "t.dir", rel + ".o")
            os.makedirs(os.path.dirname(obj), exist_ok=True)
            subprocess.run([os.environ.get("CC", "cc"), "-c", "-I", os.path.join(d, "src"),
                            os.path.join(d, rel), "-o", obj], check=True)
    return d


BASE = {"src/base/base.h": "", "src/points/points.h": '#include "base/base.h"\n',
        "src/engine/engine.h": '#include "points/points.h"\n', "src/io/io.h": "", "cli/cli.h": ""}


class Layers(unittest.TestCase):
    def run_on(self, extra):
        files = dict(BASE)
        files.update(extra)
        return subprocess.run(CHECK + [tree(files)], capture_output=True, text=True)

    def run_built(self, files, *flags):
        d = built(files)
        return subprocess.run(CHECK + ["--build", os.path.join(d, "build"), *flags, d],
                              capture_output=True, text=True)

    def test_this_tree_keeps_its_layers(self):
        r = subprocess.run(CHECK + (["--build", BUILD, "--cli"] if BUILD else []), capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout)

    def test_an_outsider_including_a_private_header_fails(self):
        r = self.run_on({"src/engine/tree.h": "", "src/api.c": '#include "engine/tree.h"\n'})
        self.assertEqual(r.returncode, 1)
        self.assertIn("private to src/engine/", r.stdout)

    def test_a_folder_including_its_own_private_header_passes(self):
        r = self.run_on({"src/engine/tree.h": "", "src/engine/x.c": '#include "engine/tree.h"\n'})
        self.assertEqual(r.returncode, 0, r.stdout)

    def test_a_lower_object_using_a_higher_symbol_fails(self):
        r = self.run_built({"src/engine/e.c": "int hd__engine_run(void) { return 1; }\n",
                            "src/points/p.c": "int hd__engine_run(void);\nint hd__p(void) { return hd__engine_run(); }\n"})
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("src/points/p.c: src/points/ (layer 1) uses hd__engine_run", r.stdout)

    def test_a_sibling_using_a_siblings_symbol_fails(self):
        r = self.run_built({"src/io/r.c": "int hd__read(void) { return 1; }\n",
                            "src/engine/e.c": "int hd__read(void);\nint hd__e(void) { return hd__read(); }\n"})
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("siblings never use each other", r.stdout)

    def test_a_higher_object_using_a_lower_symbol_passes(self):
        r = self.run_built({"src/points/p.c": "int hd__p(void) { return 1; }\n",
                            "src/engine/e.c": "int hd__p(void);\nint hd__e(void) { return hd__p(); }\n"})
        self.assertEqual(r.returncode, 0, r.stdout)

    def test_a_header_declaring_a_higher_layers_function_fails(self):
        # what engine.h did with the public index's hd__index_nearest_by
        r = self.run_built({"src/engine/engine.h": "int hd__index_nearest_by(int path);\n",
                            "src/index.c": "int hd__index_nearest_by(int path) { return path; }\n"})
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("src/engine/engine.h:1: declares hd__index_nearest_by, defined in src/index.c", r.stdout)

    def test_calls_in_an_inline_body_are_not_declarations(self):
        r = self.run_built({"src/index.c": "int hd__index_n(int p) { return p; }\n",
                            "src/engine/engine.h": "static inline int hd__e(int p) {\n    return hd__index_n(p);\n}\n"})
        self.assertNotIn("declares hd__index_n", r.stdout)

    def test_a_cycle_inside_a_folder_fails(self):
        r = self.run_built({"src/engine/a.c": "int hd__b(int);\nint hd__a(int n) { return n ? hd__b(n - 1) : 0; }\n",
                            "src/engine/b.c": "int hd__a(int);\nint hd__b(int n) { return n ? hd__a(n - 1) : 1; }\n"})
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("src/engine: its files use each other in a cycle (src/engine/a.c -> src/engine/b.c", r.stdout)

    def test_a_cycle_in_cli_fails_only_when_asked(self):
        files = {"cli/a.c": "int b(int);\nint a(int n) { return n ? b(n - 1) : 0; }\n",
                 "cli/b.c": "int a(int);\nint b(int n) { return n ? a(n - 1) : 1; }\n",
                 "src/points/p.c": "int hd__p(void) { return 1; }\n"}
        self.assertEqual(self.run_built(files).returncode, 0)
        r = self.run_built(files, "--cli")
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("cli: its files use each other in a cycle", r.stdout)

    def test_a_lower_layer_including_a_higher_one_fails(self):
        r = self.run_on({"src/points/x.c": '#include "engine/engine.h"\n'})
        self.assertEqual(r.returncode, 1)
        self.assertIn("src/points/x.c:1", r.stdout)

    def test_siblings_including_each_other_fails(self):
        r = self.run_on({"src/engine/x.c": '#include "io/io.h"\n'})
        self.assertEqual(r.returncode, 1)

    def test_a_relative_path_up_fails(self):
        r = self.run_on({"src/io/x.c": '#include "../points/points.h"\n'})
        self.assertEqual(r.returncode, 1)

    def test_cli_including_an_internal_header_fails(self):
        r = self.run_on({"cli/x.c": '#include "engine/engine.h"\n'})
        self.assertEqual(r.returncode, 1)

    def test_an_api_test_including_an_internal_header_fails(self):
        r = self.run_on({"tests/api/test_x.c": '#include "engine/engine.h"\n'})
        self.assertEqual(r.returncode, 1)
        self.assertIn("tests/api/test_x.c:1", r.stdout)

    def test_an_api_test_including_support_headers_passes(self):
        r = self.run_on({"tests/support/check.h": "", "tests/api/test_x.c": '#include "hausdorff.h"\n#include "check.h"\n'})
        self.assertEqual(r.returncode, 0, r.stdout)

    def test_the_top_including_any_layer_passes(self):
        r = self.run_on({"src/api.c": '#include "engine/engine.h"\n#include "io/io.h"\n#include "hausdorff.h"\n'})
        self.assertEqual(r.returncode, 0, r.stdout)


if __name__ == "__main__":
    unittest.main(verbosity=2)
