"""The reservoir's calibration tables from a design with its own rubber: the tables of a
Neo-Hookean sheet of the rubber's initial shear modulus (the tables are dimensionless), with a note."""
import csv

from softhand.reduced.vocabulary.design_files import design_from_dict
from softhand.studies.reservoir import ReservoirStudy, write_calibration


def _rows(path):
    with open(path, newline="") as f:
        return [row for row in csv.reader(line for line in f if not line.startswith("#"))]


def test_a_rubber_design_writes_the_neo_hookean_sheets_tables(tmp_path, capsys):
    yeoh = design_from_dict({"reservoir_model": "fem",
                             "reservoir": {"material": {"model": "yeoh", "C10_MPa": 0.5, "C20_MPa": 0.01}}})
    plain = yeoh.replace(reservoir_material=None)
    n = write_calibration(ReservoirStudy(design=yeoh, n_radial=6, n_thick=1), tmp_path / "yeoh.csv")
    assert "Neo-Hookean sheet" in capsys.readouterr().err
    assert n == write_calibration(ReservoirStudy(design=plain, n_radial=6, n_thick=1), tmp_path / "nh.csv")
    rows = _rows(tmp_path / "yeoh.csv")
    assert len(rows) == n + 1 and rows == _rows(tmp_path / "nh.csv")
