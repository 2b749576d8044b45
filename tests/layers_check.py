#!/usr/bin/env python3
"""The layering check passes on this tree and fails on trees that break it.

Each case copies nothing: it writes a tiny tree with one include and runs
scripts/check_layers.py on it, expecting the given exit status."""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHECK = [sys.executable, os.path.join(ROOT, "scripts", "check_layers.py")]


def tree(files):
    d = tempfile.mkdtemp(prefix="hd-layers-")
    for rel, text in files.items():
        p = os.path.join(d, rel)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "w") as f:
            f.write(text)
    return d


BASE = {"src/base/base.h": "", "src/points/points.h": '#include "base/base.h"\n',
        "src/engine/engine.h": '#include "points/points.h"\n', "src/io/io.h": "", "cli/cli.h": ""}


class Layers(unittest.TestCase):
    def run_on(self, extra):
        files = dict(BASE)
        files.update(extra)
        return subprocess.run(CHECK + [tree(files)], capture_output=True, text=True)

    def test_this_tree_keeps_its_layers(self):
        r = subprocess.run(CHECK, capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stdout)

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
