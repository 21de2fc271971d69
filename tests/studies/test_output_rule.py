"""The outputs rule (docs/outputs.md): a run writes only the files its manifest names, into a
private staging folder renamed into place when complete; it never deletes what it did not
write, never writes over an input; a write the disk refuses after the work is one warning,
exit code 3, the results printed and every finished piece kept."""
import errno
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from softhand.reduced.vocabulary.errors import InputError
from softhand.studies.cli.main import main
from softhand.studies.io import files
from softhand.studies.io.files import EXIT_UNWRITTEN
from softhand.studies.io.outputs import INCOMPLETE, MANIFEST, replaced_outputs

ROOT = Path(__file__).resolve().parents[2]
TASK = ROOT / "studies" / "designs" / "tasks" / "paper_task.toml"


def _listing(folder: Path) -> dict:
    """{relative path: bytes or 'folder'} of everything under ``folder``."""
    return {p.relative_to(folder).as_posix(): "folder" if p.is_dir() else p.read_bytes()
            for p in sorted(folder.rglob("*"))}


def _run_into(folder, names, write, **kw):
    with replaced_outputs(folder, names, **kw) as stage:
        write(stage)


def _partly(out, code, message):
    """A run's writing that writes b.txt, then finds the disk refusing a.txt."""
    def write(stage):
        (stage / "b.txt").write_text("written")
        with files.kept_if_unwritable(out / "a.txt", "test"):
            raise OSError(code, message)
    return write


# ------------------------------------------------------------------ the mechanism itself
def test_a_run_replaces_only_its_own_earlier_outputs_and_commits_whole(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("the user's")

    def first(stage):
        (stage / "a.txt").write_text("first")
        (stage / "sub").mkdir()
        (stage / "sub" / "x.txt").write_text("first")

    _run_into(out, ("a.txt", "sub"), first)
    assert json.loads((out / MANIFEST).read_text())["outputs"] == ["a.txt", "sub"]
    assert (out / "sub" / "x.txt").read_text() == "first"
    _run_into(out, ("a.txt", "sub"), lambda stage: (stage / "a.txt").write_text("second"))
    # the earlier run's sub/ was its own: gone; the user's file stays; no staging folder stays
    assert _listing(out) == {MANIFEST: (out / MANIFEST).read_bytes(), "a.txt": b"second",
                             "notes.txt": b"the user's"}


def test_a_run_leaves_another_verbs_outputs_and_names_the_manifest_was_given(tmp_path):
    """Two verbs into one folder: each replaces its own earlier outputs only; a name of the
    user's written into the manifest by hand is not this verb's output: never deleted."""
    out = tmp_path / "out"
    _run_into(out, ("a.txt",), lambda stage: (stage / "a.txt").write_text("verb A"))
    _run_into(out, ("b.txt", "sub"), lambda stage: (stage / "b.txt").write_text("verb B"))
    assert json.loads((out / MANIFEST).read_text())["outputs"] == ["a.txt", "b.txt"]
    record = json.loads((out / MANIFEST).read_text())
    (out / "notes.txt").write_text("the user's")
    (out / MANIFEST).write_text(json.dumps({**record, "outputs": record["outputs"] + ["notes.txt"]}))
    _run_into(out, ("a.txt",), lambda stage: (stage / "a.txt").write_text("verb A again"))
    assert _listing(out) == {MANIFEST: (out / MANIFEST).read_bytes(), "a.txt": b"verb A again",
                             "b.txt": b"verb B", "notes.txt": b"the user's"}


def test_an_earlier_output_the_user_changed_is_refused_before_the_work(tmp_path):
    """A file of the user's put into an earlier run's output folder, a folder or a link where
    the run wrote a file, a link where it wrote a folder: refused before the work, untouched."""
    out = tmp_path / "out"

    def write(stage):
        (stage / "a.txt").write_text("run")
        (stage / "sub").mkdir()
        (stage / "sub" / "x.txt").write_text("run")

    _run_into(out, ("a.txt", "sub"), write)
    (out / "sub" / "mine.txt").write_text("the user's")
    with pytest.raises(InputError, match="sub/mine.txt.*not written by an earlier softhand run"):
        _run_into(out, ("a.txt", "sub"), write)
    assert (out / "sub" / "mine.txt").read_text() == "the user's"
    (out / "sub" / "mine.txt").unlink()
    _run_into(out, ("a.txt", "sub"), write)  # the folder as the run left it: replaced
    (out / "a.txt").unlink()
    (out / "a.txt").mkdir()
    (out / "a.txt" / "data.txt").write_text("the user's")
    with pytest.raises(InputError, match="is a folder where an earlier softhand run wrote a file"):
        _run_into(out, ("a.txt", "sub"), write)
    assert (out / "a.txt" / "data.txt").read_text() == "the user's"
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (out / "a.txt" / "data.txt").rename(elsewhere / "data.txt")
    (out / "a.txt").rmdir()
    (out / "a.txt").write_text("run")
    os.rename(out / "sub", tmp_path / "moved")
    (out / "sub").symlink_to(elsewhere, target_is_directory=True)
    with pytest.raises(InputError, match="is a link where an earlier softhand run wrote a folder"):
        _run_into(out, ("a.txt", "sub"), write)
    assert _listing(elsewhere) == {"data.txt": b"the user's"}


def test_a_file_named_on_the_command_line_replaces_only_its_own_earlier_self(tmp_path, monkeypatch, capsys):
    """--plot FILE / --out FILE.toml: a file of the user's there, or a run's output of that name,
    is refused before the work; the file this option wrote before is replaced; the inspect
    default picture likewise."""
    monkeypatch.chdir(tmp_path)
    Path("photo.png").write_bytes(b"the user's")
    assert main(["curve", "--theta-deg", "10,20", "--plot", "photo.png"]) == 2
    assert "photo.png" in capsys.readouterr().err and Path("photo.png").read_bytes() == b"the user's"
    assert main(["curve", "--theta-deg", "10,20", "--plot", "fig.png"]) == 0
    first = Path("fig.png").stat().st_mtime_ns
    assert main(["curve", "--theta-deg", "10,30", "--plot", "fig.png"]) == 0  # its own: replaced
    assert Path("fig.png").stat().st_mtime_ns >= first
    _run_into(Path("run"), ("design.toml",), lambda stage: (stage / "design.toml").write_text("a run's"))
    Path("data.csv").write_text("theta_deg,P_MPa\n10,0.1\n20,0.2\n30,0.3\n")
    assert main(["fit", "--data", "data.csv", "--params", "V0_mm3", "--out", "run/design.toml"]) == 2
    assert Path("run/design.toml").read_text() == "a run's"
    # and a run into a folder leaves a file an option wrote there alone
    _run_into(Path("."), ("a.txt",), lambda stage: (stage / "a.txt").write_text("run"))
    assert Path("fig.png").exists() and Path("photo.png").read_bytes() == b"the user's"
    with pytest.raises(InputError, match="another softhand command wrote there"):
        _run_into(Path("."), ("fig.png",), lambda stage: None)


def test_a_name_inside_an_output_folder_that_changed_kind_and_another_verbs_file_are_refused(tmp_path):
    """Inside an earlier run's output folder, a file replaced by a link or a folder: refused like
    a file added there; another verb's output of the same name (two verbs' result.json): refused."""
    out = tmp_path / "out"

    def write(stage):
        (stage / "result.json").write_text("bend's")
        (stage / "sub" / "deep").mkdir(parents=True)
        (stage / "sub" / "x.vtu").write_text("run")

    _run_into(out, ("result.json", "sub"), write, verb="bend")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    for change in ("link", "folder"):
        (out / "sub" / "x.vtu").unlink()
        if change == "link":
            (out / "sub" / "x.vtu").symlink_to(elsewhere / "y.vtu")
        else:
            (out / "sub" / "x.vtu").mkdir()
        with pytest.raises(InputError, match="sub/x.vtu'.*not written by an earlier softhand run"):
            _run_into(out, ("result.json", "sub"), write, verb="bend")
        (out / "sub" / "x.vtu").unlink() if change == "link" else (out / "sub" / "x.vtu").rmdir()
        (out / "sub" / "x.vtu").write_text("run")
    with pytest.raises(InputError, match="was written by softhand bend, and softhand hold writes its own"):
        _run_into(out, ("result.json", "hold.pvd"), lambda stage: None, verb="hold")
    assert (out / "result.json").read_text() == "bend's"
    _run_into(out, ("result.json", "sub"), write, verb="bend")  # its own: replaced


def test_a_stopped_run_leaves_the_earlier_result_whole(tmp_path):
    out = tmp_path / "out"
    _run_into(out, ("a.txt", "sub"), lambda stage: (stage / "a.txt").write_text("complete"))
    before = _listing(out)

    def stopped(stage):
        (stage / "a.txt").write_text("half")
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        _run_into(out, ("a.txt", "sub"), stopped)
    assert _listing(out) == before
    fresh = tmp_path / "fresh"
    with pytest.raises(KeyboardInterrupt):  # a folder the stopped run made goes too
        _run_into(fresh, ("a.txt",), stopped)
    assert not fresh.exists()
    with pytest.raises(KeyboardInterrupt):  # and every folder it made on the way (results/bend)
        _run_into(fresh / "results" / "bend", ("a.txt",), stopped)
    assert not fresh.exists()
    (tmp_path / "mine").mkdir()
    with pytest.raises(KeyboardInterrupt):  # the user's folder stays, so does a file put in one meanwhile
        _run_into(tmp_path / "mine" / "results" / "bend", ("a.txt",),
                  lambda stage: ((tmp_path / "mine" / "results" / "note").write_text("x"), stopped(stage)))
    assert sorted(p.name for p in (tmp_path / "mine").rglob("*")) == ["note", "results"]


def test_an_output_name_the_user_holds_is_refused_not_deleted(tmp_path):
    out = tmp_path / "out"
    (out / "sub").mkdir(parents=True)
    (out / "sub" / "mine.txt").write_text("the user's")
    with pytest.raises(InputError, match="not written by an earlier softhand run"):
        _run_into(out, ("a.txt", "sub"), lambda stage: None)
    assert _listing(out) == {"sub": "folder", "sub/mine.txt": b"the user's"}


def test_a_write_the_disk_refuses_keeps_the_earlier_result_and_the_pieces_written(tmp_path, capsys):
    out = tmp_path / "out"
    _run_into(out, ("a.txt", "b.txt"), lambda stage: (stage / "a.txt").write_text("complete"))
    before = _listing(out)
    files.reset_unwritten()

    _run_into(out, ("a.txt", "b.txt"), _partly(out, errno.EFBIG, "File too large"))
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "a.txt (File too large) not written" in err and f"exit code {EXIT_UNWRITTEN}" in err
    assert files.UNWRITTEN == [f"{out / 'a.txt'} (File too large)"]
    after = _listing(out)
    assert {k: v for k, v in after.items() if not k.startswith(INCOMPLETE) and k != MANIFEST} == \
        {k: v for k, v in before.items() if k != MANIFEST}  # the earlier result whole
    assert (out / INCOMPLETE / "b.txt").read_text() == "written"
    record = json.loads((out / INCOMPLETE / MANIFEST).read_text())
    assert record["complete"] is False and record["missing"] == [f"{out / 'a.txt'} (File too large)"]
    files.reset_unwritten()
    # the next complete run replaces the incomplete one's folder too: it was a run's
    _run_into(out, ("a.txt", "b.txt"), lambda stage: (stage / "a.txt").write_text("third"))
    assert not (out / INCOMPLETE).exists() and (out / "a.txt").read_text() == "third"


def test_a_users_folder_named_incomplete_neither_blocks_a_run_nor_is_touched(tmp_path, capsys):
    out = tmp_path / "out"
    (out / INCOMPLETE).mkdir(parents=True)
    (out / INCOMPLETE / "draft.txt").write_text("the user's")
    _run_into(out, ("a.txt", "b.txt"), lambda stage: (stage / "a.txt").write_text("complete"))
    assert (out / "a.txt").read_text() == "complete"
    files.reset_unwritten()

    _run_into(out, ("a.txt", "b.txt"), _partly(out, errno.ENOSPC, "No space left on device"))
    files.reset_unwritten()
    kept = [p for p in out.iterdir() if p.name.startswith(f"{INCOMPLETE}-")]
    assert len(kept) == 1 and (kept[0] / "b.txt").read_text() == "written"
    assert str(kept[0]) in capsys.readouterr().err  # the warning says where the pieces are
    assert _listing(out / INCOMPLETE) == {"draft.txt": b"the user's"}
    # the next complete run replaces its own incomplete pieces, never the user's folder
    _run_into(out, ("a.txt", "b.txt"), lambda stage: (stage / "a.txt").write_text("third"))
    assert not kept[0].exists() and _listing(out / INCOMPLETE) == {"draft.txt": b"the user's"}


def test_reproduce_refuses_an_output_name_the_user_holds_and_resumes_its_own(tmp_path):
    from softhand.studies.reproduce.core import reproduce

    out = tmp_path / "out"
    (out / "fig7_reduced").mkdir(parents=True)
    (out / "fig7_reduced" / "mine.txt").write_text("the user's")
    (out / "report.md").write_text("the user's report")
    only = ("fig7_reduced",)
    with pytest.raises(InputError, match="report.md.*not written by an earlier softhand run"):
        reproduce(out, quick=True, only=only, progress=False)
    (out / "report.md").unlink()
    with pytest.raises(InputError, match="fig7_reduced.*not written by an earlier softhand run"):
        reproduce(out, quick=True, only=only, progress=False)
    assert _listing(out) == {"fig7_reduced": "folder", "fig7_reduced/mine.txt": b"the user's"}
    (out / "fig7_reduced" / "mine.txt").unlink()
    (out / "fig7_reduced").rmdir()
    assert [o.status for o in reproduce(out, quick=True, only=only, progress=False)][0] == "done"
    assert set(json.loads((out / MANIFEST).read_text())["outputs"]) == {"fig7_reduced", "report.md", "summary.csv"}
    assert [o.status for o in reproduce(out, quick=True, only=only, progress=False)][0] == "reused"


def test_reproduce_resumes_sections_an_earlier_version_left_without_a_manifest(tmp_path):
    from softhand.studies.reproduce.core import reproduce

    out = tmp_path / "out"
    only = ("fig7_reduced",)
    reproduce(out, quick=True, only=only, progress=False)
    (out / MANIFEST).unlink()  # as an earlier softhand left it
    assert [o.status for o in reproduce(out, quick=True, only=only, progress=False)][0] == "reused"
    (out / MANIFEST).unlink()
    (out / "fig7_reduced" / "result.json").write_text('{"section": "table2_reduced"}')  # not this section's
    with pytest.raises(InputError, match="not written by an earlier softhand run"):
        reproduce(out, quick=True, only=only, progress=False)
    assert not (out / MANIFEST).exists()


def test_a_killed_runs_staging_folder_is_removed_by_the_next_run(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    stale = out / f".softhand-stage-{gone}-deadbeef"
    (stale / "a.txt").parent.mkdir()
    (stale / "a.txt").write_text("half of a killed run")
    _run_into(out, ("a.txt",), lambda stage: (stage / "a.txt").write_text("complete"))
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "a.txt"]


# ------------------------------------------------------------------ the verbs: never anyone else's
@pytest.mark.parametrize("argv, mine", [
    (["design", "--task", str(TASK), "--no-fem", "--no-progress"], "grasp"),
    (["design", "--task", str(TASK), "--no-fem", "--no-progress"], "knee"),
    (["bend", "--pressure-mpa", "0.1"], "finger"),
    (["weights", "--diameter-mm", "180"], "grasp"),
    (["reservoir", "--volume-mm3", "16000"], "sheet"),
])
def test_out_never_deletes_a_users_folder_of_an_outputs_name(tmp_path, capsys, argv, mine):
    """design removed DIR/grasp/ and DIR/knee/ (even with --no-fem), bend DIR/finger/, weights
    DIR/grasp/, reservoir DIR/sheet/: now refused before any work, exit 2, all kept."""
    out = tmp_path / "out"
    (out / mine).mkdir(parents=True)
    (out / mine / "thesis.tex").write_text("the user's")
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{out / mine}" in err[0] and "not written by an earlier softhand run" in err[0]
    assert _listing(out) == {mine: "folder", f"{mine}/thesis.tex": b"the user's"}


def test_design_reruns_replace_their_own_result_whole(tmp_path, capsys):
    out = tmp_path / "d"
    argv = ["design", "--task", str(TASK), "--no-fem", "--no-progress", "--json", "--out", str(out)]
    assert main(argv) == 0
    first = json.loads((out / MANIFEST).read_text())
    assert first["outputs"] == ["design.toml", "result.json"] and first["verb"] == "design"
    assert json.loads((out / "result.json").read_text())["design_file"] == str(out / "design.toml")
    assert main(argv) == 0
    assert json.loads((out / MANIFEST).read_text())["run"] != first["run"]
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "design.toml", "result.json"]


def test_a_task_named_dots_cannot_name_the_results_folder_itself(tmp_path, monkeypatch, capsys):
    """A task file named '...toml' gave the default folder results/design/.. = results/: it
    overwrote results/result.json and deleted results/grasp/."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "...toml").write_text(TASK.read_text())
    (tmp_path / "results" / "grasp").mkdir(parents=True)
    (tmp_path / "results" / "result.json").write_text("another run's")
    before = _listing(tmp_path)
    assert main(["design", "--task", "...toml", "--no-fem", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "cannot name the output folder" in err and "--out" in err
    assert _listing(tmp_path) == before


# ------------------------------------------------------------------ never over an input
def _fake_calibration(monkeypatch, calls):
    """calibrate finger's FEM and table replaced: what matters here is where the files go."""
    from softhand.studies.calibration import finger_table
    from softhand.studies.cli.verbs import calibrate

    def fake_run(space, args):
        calls.append(space)
        return [(d, {"numbers": {}}) for d in space.designs()]

    def fake_table(path, space, results, command):
        return files.write_atomic(path, "# a table\n")

    monkeypatch.setattr(calibrate, "_run", fake_run)
    monkeypatch.setattr(finger_table, "write_table", fake_table)


def test_calibrate_finger_design_never_writes_over_its_design(tmp_path, monkeypatch, capsys):
    """The README's 'calibrate finger --design my.toml --out my.csv' overwrote my.toml, comments
    and all, with the generated design. The design using the table is my_fem.toml."""
    calls = []
    _fake_calibration(monkeypatch, calls)
    mine = tmp_path / "my.toml"
    mine.write_text("# my finger, with my notes\na_mm = 4.0\nb_mm = 5.0\n")
    text = mine.read_text()
    assert main(["calibrate", "finger", "--design", str(mine), "--out", str(tmp_path / "my.csv")]) == 0
    assert mine.read_text() == text
    made = (tmp_path / "my_fem.toml").read_text()
    assert made.startswith("# softhand calibrate finger") and 'finger_table = "my.csv"' in made
    assert main(["calibrate", "finger", "--design", str(mine), "--out", str(tmp_path / "my.csv")]) == 0
    # an input in the design file's place, a folder or a file of the user's: refused before any FEM
    calls.clear()
    capsys.readouterr()
    for argv in (["--design", str(tmp_path / "my_fem.toml"), "--out", str(tmp_path / "my.csv")],
                 ["--design", str(mine), "--out", str(tmp_path / "dir.csv")],
                 ["--design", str(mine), "--out", str(tmp_path / "users.csv")]):
        (tmp_path / "dir_fem.toml").mkdir(exist_ok=True)
        (tmp_path / "users_fem.toml").write_text("my own file\n")
        assert main(["calibrate", "finger", *argv]) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert calls == [] and (tmp_path / "users_fem.toml").read_text() == "my own file\n"


def test_calibrate_keeps_its_fem_cases_when_the_table_cannot_be_written(tmp_path, monkeypatch, capsys):
    from softhand.studies.calibration import finger_table

    _fake_calibration(monkeypatch, [])

    def full(path, space, results, command):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(finger_table, "write_table", full)
    mine = tmp_path / "my.toml"
    mine.write_text("a_mm = 4.0\n")
    assert main(["calibrate", "finger", "--design", str(mine), "--out", str(tmp_path / "my.csv")]) == EXIT_UNWRITTEN
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "No space left on device" in err[0] and "--finished" in err[0]


# ------------------------------------------------------------------ smaller findings
def test_grasp_weights_is_no_range(capsys):
    assert main(["grasp", "--pressure-mpa", "0.5", "--theta-deg", "40", "--mass-kg", "1",
                 "--weights", "0:1:0.25"]) == 2
    assert "not a range" in capsys.readouterr().err


@pytest.mark.parametrize("rows", ["0.3,40\n" * 4, "0,0\n" * 3])
def test_fit_on_repeated_or_zero_points_says_the_data_cannot_identify(tmp_path, capsys, rows):
    """Four copies of one point (or all zeros) had standard errors of 0 or 1e-9: a fit the data
    never measured."""
    data = tmp_path / "d.csv"
    data.write_text("P_MPa,theta_deg\n" + rows)
    assert main(["fit", "--data", str(data), "--params", "mu_sf_MPa"]) == 2
    err = capsys.readouterr().err
    assert "1 distinct" in err and "cannot identify" in err


def test_a_study_reads_its_inline_finger_table_next_to_itself(tmp_path, monkeypatch):
    """[design] finger_table = "t.csv" was read from the current folder: another t.csv there was
    used silently."""
    from softhand.reduced.calibrated.finger_fem_table import TABLE_FILE
    from softhand.studies.batch.studyfile import load_study

    (tmp_path / "study").mkdir()
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "study" / "t.csv").write_text(TABLE_FILE.read_text())
    (tmp_path / "elsewhere" / "t.csv").write_text(TABLE_FILE.read_text())
    path = tmp_path / "study" / "s.toml"
    path.write_text('kind = "curve"\n[design]\nfinger_model = "fem"\nfinger_table = "t.csv"\n'
                    '[sweep]\ntheta_deg = [10]\n')
    monkeypatch.chdir(tmp_path / "elsewhere")
    assert load_study(path).design.finger_table == str(tmp_path / "study" / "t.csv")


def test_a_table_answers_only_on_its_own_designs(tmp_path):
    """A table of 3 designs over tie widths 8..12 mm that declares 5..15 mm (as a few designs of
    a wide box did): the model refuses 14 mm, where no design of it was measured, and answers
    at 9 mm."""
    from synthetic_tables import synthetic_table

    from softhand.reduced.equations import hand
    from softhand.reduced.calibrated.finger_fem import groups_of

    path, designs, _ = synthetic_table(tmp_path, ties=(8.0, 10.0, 12.0))
    wide = groups_of(designs[0].replace(tie_width=5.0))["tie_link"], groups_of(designs[0].replace(tie_width=15.0))["tie_link"]
    lines = path.read_text().splitlines()
    lines = [line if not line.startswith("# range:") else
             ", ".join(part if not part.lstrip("# range:").startswith("tie_link") else
                       f"tie_link={wide[0]!r}:{wide[1]!r}" for part in line.split(", "))
             for line in lines]
    assert any(f"tie_link={wide[0]!r}" in line for line in lines)
    path.write_text("\n".join(lines) + "\n")
    fem = designs[0].replace(finger_model="fem", finger_table=str(path))
    assert hand.bend_angle(0.5, fem.replace(tie_width=9.0), reservoir=False) > 0
    with pytest.raises(InputError, match="outside the range"):
        hand.bend_angle(0.5, fem.replace(tie_width=14.0), reservoir=False)


def test_a_mesh_cache_entry_swapped_with_its_checksum_is_not_used(tmp_path):
    from softhand.meshes import cache

    a, b = tmp_path / "a.msh", tmp_path / "b.msh"
    for path, text in ((a, "mesh A"), (b, "mesh B")):
        path.write_text(text)
        Path(f"{path}.sha256").write_text(f"{cache._sha256(path)}  {path.name}\n")  # noqa: SLF001
    assert cache.valid_entry(a) and cache.valid_entry(b)
    b.write_bytes(a.read_bytes())  # A copied over B, together with its checksum
    Path(f"{b}.sha256").write_bytes(Path(f"{a}.sha256").read_bytes())
    assert not cache.valid_entry(b)
    os.mkfifo(f"{a}.sha256.fifo")
    os.replace(f"{a}.sha256.fifo", f"{a}.sha256")  # a FIFO where the checksum goes: no wait
    assert not cache.valid_entry(a)


def test_meshes_of_an_unwritable_cache_are_removed_at_exit(tmp_path):
    code = ("from softhand.meshes import cache; p = cache._scratch_folder(); (p / 'x.msh').write_text('m'); "
            "print(p)")
    folder = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True).stdout.strip()
    assert folder and not Path(folder).exists()


def test_an_edited_manifest_cannot_point_a_run_outside_its_folder(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "precious.txt").write_text("outside the folder")
    (out / MANIFEST).write_text(json.dumps({"run": "x", "outputs": ["../precious.txt", "/etc", ".", "a.txt"]}))
    _run_into(out, ("a.txt",), lambda stage: (stage / "a.txt").write_text("new"))
    assert (tmp_path / "precious.txt").read_text() == "outside the folder"
    assert json.loads((out / MANIFEST).read_text())["outputs"] == ["a.txt"]


def test_a_manifest_that_is_no_plain_file_is_one_line(tmp_path):
    out = tmp_path / "out"
    (out / MANIFEST).mkdir(parents=True)
    with pytest.raises(InputError, match="no plain file"):
        _run_into(out, ("a.txt",), lambda stage: None)


@pytest.mark.slow  # two Pareto fronts: minutes
def test_design_pareto_plot_named_inside_its_folder_is_staged_with_it(tmp_path, capsys):
    out = tmp_path / "d"
    argv = ["design", "--task", str(TASK), "--no-fem", "--no-progress", "--json", "--pareto", "--out", str(out),
            "--plot", str(out / "pareto.png")]
    assert main(argv) == 0
    assert main(argv) == 0  # the earlier run's plot is replaced by this run's, not removed after it
    assert (out / "pareto.png").stat().st_size > 0
    assert "pareto.png" in json.loads((out / MANIFEST).read_text())["outputs"]
