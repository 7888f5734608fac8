"""The worked example of docs/python.md, run as it stands, and the module's error path.

Run by ctest (python_docs_example) with PYTHONPATH at build/python and PNEUMA_DOCS at docs/python.md.
"""
import os
import re
import tempfile
import unittest


def docs_example():
    """The first python block under '## Example' in docs/python.md."""
    text = open(os.environ["PNEUMA_DOCS"], encoding="utf-8").read()
    section = text[text.index("## Example"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


class DocsExample(unittest.TestCase):
    def test_weaker_diaphragm_breathes_shallower_and_both_volumes_are_plotted(self):
        code = docs_example()
        with tempfile.TemporaryDirectory() as work:
            cwd = os.getcwd()
            os.chdir(work)
            try:
                scope = {}
                exec(compile(code, "docs/python.md", "exec"), scope)
                self.assertGreater(os.path.getsize("calm_vs_diaphragm.png"), 1000)
            finally:
                os.chdir(cwd)
        # the calm breath of the default model is about 500 mL (Zordan et al. 2004, Figure 6)
        self.assertGreater(scope["tidal_before"], 350.0)
        self.assertLess(scope["tidal_before"], 700.0)
        # a diaphragm a quarter as strong moves less air (about 10 % less: 473 against 526 mL in the CLI)
        self.assertLess(scope["tidal_after"], scope["tidal_before"] * 0.95)


class Errors(unittest.TestCase):
    def test_bad_override_names_the_key(self):
        import pneuma
        run = pneuma.Simulation(pneuma.load_model(), style="calm")
        with self.assertRaisesRegex(pneuma.Error, r"^set: dt_s: must be in \[1e-06, 0.05\] s, got 1$"):
            run.set("dt_s", 1)
        with self.assertRaisesRegex(pneuma.Error, r"dt: unknown field \(did you mean dt_s\?\)"):
            run.set("dt", 0.01)
        with self.assertRaisesRegex(pneuma.Error, "unknown breath style 'yodel'"):
            pneuma.Simulation(pneuma.load_model(), style="yodel")

    def test_state_views_follow_the_run_without_a_copy(self):
        import pneuma
        model = pneuma.load_model()
        run = pneuma.Simulation(model, style="calm", settle_time=0.1)
        nodes = run.node_positions
        self.assertEqual(nodes.shape, (3, model.node_count))
        self.assertFalse(nodes.flags.writeable)
        before = nodes.copy()
        run.run(0.5)
        # the same view now shows the moved nodes (gravity and the drive move the free ones)
        self.assertGreater(abs(nodes - before).max(), 1e-6)


if __name__ == "__main__":
    unittest.main()
