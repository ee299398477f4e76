"""Tests of the regeneration script's own machinery (standard library):
`python3 -m unittest discover -s scripts/regendocs -t scripts` (CI runs it).
The spot check runs the `cpsplan` binary of this checkout."""

import copy
import json
import subprocess
import sys
import tempfile
import tomllib
import unittest
from pathlib import Path

from regendocs import ledger
from regendocs.common import ROOT, median, median_range, percent_share, toml_of

SCRIPT = ROOT / "scripts" / "regen-docs"


class Formats(unittest.TestCase):
    def test_a_share_never_reads_whole_before_it_is(self):
        self.assertEqual(percent_share(0.99996, 1), "99.9")
        self.assertEqual(percent_share(1.0, 1), "100.0")
        self.assertEqual(percent_share(0.00001, 1), "0.1")

    def test_the_median_of_an_even_count_is_the_mean_of_the_middle_two(self):
        self.assertEqual(median([4, 1, 3, 2]), 2.5)
        self.assertEqual(median_range([5.0, 1.0, 9.0], 1), "5.0 (1.0–9.0)")
        self.assertEqual(median_range([], 1), "—")

    def test_a_configuration_reads_back_from_its_toml(self):
        config = {"seed": 3, "parent": {"alpha": 1e-05, "planner": "tour", "viewpoints": True, "max_range": None},
                  "time": {"scan_s": 180.0}}
        back = tomllib.loads(toml_of(config))
        expected = copy.deepcopy(config)
        del expected["parent"]["max_range"]
        self.assertEqual(back, expected)


class Ledger(unittest.TestCase):
    def spot(self):
        entries = [s for e in ledger.read().values() for s in e["spots"] if not ledger.needs_shared(s)]
        if not entries:
            self.skipTest("SKIPPED: the ledger holds no spot check on the project's maps")
        # The quickest: the one with the fewest scans.
        return min(entries, key=lambda s: s["expect"]["scans"])

    def test_a_spot_check_gives_its_recorded_figures(self):
        spot = self.spot()
        with tempfile.TemporaryDirectory() as tmp:
            self.assertEqual(ledger.check_spot(spot, tmp), [])

    def test_a_spot_check_finds_a_figure_that_moved(self):
        spot = copy.deepcopy(self.spot())
        spot["expect"]["parent_travel_m"] *= 1.0 + 1e-7
        with tempfile.TemporaryDirectory() as tmp:
            moved = ledger.check_spot(spot, tmp)
        self.assertEqual([field for field, _, _ in moved], ["parent_travel_m"])


class Documents(unittest.TestCase):
    def check(self, text, ledger_figures):
        """Runs `regen-docs --check` on a copy of the project's script over one
        document, with a ledger of one heavy source that has no spot checks."""
        with tempfile.TemporaryDirectory() as tmp:
            root = Path(tmp)
            (root / "scripts").mkdir()
            (root / "docs").mkdir()
            subprocess.run(["cp", "-r", str(SCRIPT), str(ROOT / "scripts" / "regendocs"), str(root / "scripts")],
                           check=True)
            (root / "scripts" / "regendocs" / "ledger.json").write_text(json.dumps(
                {"alpha-beta": {"inputs": {}, "figures": ledger_figures, "spots": []}}))
            (root / "README.md").write_text(text)
            (root / "docs" / "USER-GUIDE.md").write_text("")
            (root / "docs" / "RESULTS.md").write_text("")
            return subprocess.run([sys.executable, str(root / "scripts" / "regen-docs"), "--check"],
                                  capture_output=True, text=True)

    def test_figures_that_agree_pass(self):
        done = self.check("Scans: <!--=alpha-beta.fewer_where-->every map<!--/-->.\n",
                          {"fewer_where": "every map"})
        self.assertEqual(done.returncode, 0, done.stdout + done.stderr)

    def test_a_figure_that_differs_fails(self):
        done = self.check("Scans: <!--=alpha-beta.fewer_where-->every map<!--/-->.\n",
                          {"fewer_where": "the office"})
        self.assertEqual(done.returncode, 1)
        self.assertIn("the run gives 'the office'", done.stdout)

    def test_a_table_figure_stands_on_lines_of_its_own(self):
        table = "| a | b |\n|---|---|\n| 1 | 2 |"
        done = self.check("Table:\n\n<!--=alpha-beta.table-->\n| a | b |\n|---|---|\n| 1 | 2 |\n<!--/-->\n",
                          {"table": table})
        self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
        done = self.check("Table: <!--=alpha-beta.table-->\n| a | b |\n|---|---|\n| 1 | 2 |\n<!--/-->\n",
                          {"table": table})
        self.assertEqual(done.returncode, 1)
        self.assertIn("is a block", done.stdout)

    def test_a_figure_may_not_begin_a_line(self):
        done = self.check("Scans:\n<!--=alpha-beta.fewer_where-->every map<!--/--> here.\n",
                          {"fewer_where": "every map"})
        self.assertEqual(done.returncode, 1)
        self.assertIn("begins a line", done.stderr)


if __name__ == "__main__":
    unittest.main()
