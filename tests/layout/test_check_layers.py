#!/usr/bin/env python3
"""The layout checker's own test: a target folder nested in another target's folder
(gateways/iso_on_tcp inside gateways/) has its files checked against its own dependencies only.

Builds a tiny tree in a temporary folder (two targets, `outer` in a/ and `inner` in a/inner/,
each with its own include folder) and runs check_layers.main() on it.
"""
import contextlib
import io
import pathlib
import sys
import tempfile
import unittest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import check_layers  # noqa: E402


def write(root, rel, text):
    p = root / rel
    p.parent.mkdir(parents=True, exist_ok=True)
    p.write_text(text)


class NestedTargetFolder(unittest.TestCase):
    def tree(self, inner_includes, outer_includes):
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        root = pathlib.Path(tmp.name)
        write(root, "docs/architecture.md",
              "```layers\nouter (a): base\ninner (a/inner): dep\n\nbase (base):\ndep (dep):\n```\n")
        write(root, "base/CMakeLists.txt", "pbvbus_layer(NAME base)\n")
        write(root, "dep/CMakeLists.txt", "pbvbus_layer(NAME dep)\n")
        write(root, "a/CMakeLists.txt", "pbvbus_layer(NAME outer DEPS pbvbus::base)\n")
        write(root, "a/inner/CMakeLists.txt", "pbvbus_layer(NAME inner DEPS pbvbus::dep)\n")
        write(root, "base/include/pbvbus/base/b.hpp", "#pragma once\n")
        write(root, "dep/include/pbvbus/dep/d.hpp", "#pragma once\n")
        write(root, "a/src/o.cpp", "".join(f'#include "pbvbus/{i}/x.hpp"\n' for i in outer_includes))
        write(root, "a/inner/src/i.cpp",
              "".join(f'#include "pbvbus/{i}/x.hpp"\n' for i in inner_includes))
        return root

    def run_check(self, root):
        saved = check_layers.ROOT
        check_layers.ROOT = root
        out = io.StringIO()
        try:
            with contextlib.redirect_stdout(out):
                status = check_layers.main()
        finally:
            check_layers.ROOT = saved
        return status, out.getvalue()

    def test_a_nested_targets_includes_are_its_own(self):
        # inner includes dep (its dependency), which outer does not have: no problem.
        status, out = self.run_check(self.tree(inner_includes=["dep"], outer_includes=["base"]))
        self.assertEqual(status, 0, out)

    def test_the_outer_target_is_still_checked(self):
        status, out = self.run_check(self.tree(inner_includes=["dep"], outer_includes=["dep"]))
        self.assertEqual(status, 1)
        self.assertIn("a/src/o.cpp includes pbvbus/dep/", out)
        self.assertNotIn("a/inner/src/i.cpp", out)

    def test_the_nested_target_is_checked_against_its_own_dependencies(self):
        status, out = self.run_check(self.tree(inner_includes=["base"], outer_includes=["base"]))
        self.assertEqual(status, 1)
        self.assertIn("a/inner/src/i.cpp includes pbvbus/base/ of base, which inner does not", out)


if __name__ == "__main__":
    unittest.main()
