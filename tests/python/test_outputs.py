"""The module's output files are the CLI's: the same writers, so the same bytes for the same run.

Run by ctest (python_outputs) with PYTHONPATH at build/python and PNEUMA_CLI at build/bin/pneuma-cli.
"""
import json
import os
import subprocess
import tempfile
import unittest

import pneuma


class Outputs(unittest.TestCase):
    def test_a_calm_run_writes_the_same_files_as_pneuma_cli_simulate(self):
        with tempfile.TemporaryDirectory() as work:
            cli_out, py_out = os.path.join(work, "cli"), os.path.join(work, "py")
            # 10 frames per simulated second: a ParaView frame of the default model (with its skin) is large
            subprocess.run([os.environ["PNEUMA_CLI"], "simulate", "--style", "calm", "--duration", "6",
                            "--output-rate", "10", "--vtk", "--out", cli_out], check=True, capture_output=True)

            run = pneuma.Simulation(pneuma.load_model(), style="calm", output_rate=10.0)
            run.start_outputs(py_out, vtk=True)
            run.run(run.settle_time + 6.0)
            files = run.write_outputs()

            with open(os.path.join(cli_out, "summary.json")) as a, open(os.path.join(py_out, "summary.json")) as b:
                cli, py = json.load(a), json.load(b)
            self.assertEqual(files, ["summary.json"] + cli["files"])
            self.assertIn("timeseries.csv", files)
            self.assertIn("lung_volume.svg", files)
            self.assertIn("frames.pvd", files)
            # every file the CLI wrote, the module wrote with the same bytes (CSV, plots' SVG, ParaView series)
            for name in ["timeseries.csv", "lung_volume.svg", "activations.svg", "frames.pvd"]:
                with open(os.path.join(cli_out, name), "rb") as a, open(os.path.join(py_out, name), "rb") as b:
                    self.assertEqual(a.read(), b.read(), name)
            frames = sorted(os.listdir(os.path.join(cli_out, "frames")))
            self.assertEqual(frames, sorted(os.listdir(os.path.join(py_out, "frames"))))
            self.assertGreater(len(frames), 6 * 10)
            for name in [frames[0], frames[-1]]:
                with open(os.path.join(cli_out, "frames", name), "rb") as a, \
                        open(os.path.join(py_out, "frames", name), "rb") as b:
                    self.assertEqual(a.read(), b.read(), name)

            # summary.json: the same keys, and the same values but the wall-clock figure, the model path's
            # spelling (bin/.. against python/..) and the duration, which the module measures from the clock
            self.assertEqual(sorted(cli), sorted(py))
            for key in cli:
                if key in ("real_time_factor", "model", "duration_s"):
                    continue
                self.assertEqual(cli[key], py[key], key)
            self.assertAlmostEqual(py["duration_s"], 6.0, places=9)
            self.assertEqual(os.path.realpath(py["model"]), os.path.realpath(cli["model"]))
            self.assertGreater(py["tidal_volume_ml"], 350.0)  # a calm breath, not an empty summary

    def test_write_outputs_before_start_outputs_names_the_call(self):
        run = pneuma.Simulation(pneuma.load_model(), style="calm")
        with self.assertRaisesRegex(pneuma.Error, "call start_outputs"):
            run.write_outputs()


if __name__ == "__main__":
    unittest.main()
