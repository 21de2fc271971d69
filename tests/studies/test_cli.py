"""The CLI front door: help, version, unknown verbs."""
import subprocess
import sys

from softhand.studies.cli.main import main


def run(*argv):
    return subprocess.run([sys.executable, "-m", "softhand.studies.cli.main", *argv],
                          capture_output=True, text=True)


def test_version_and_help():
    out = run("--version")
    assert out.returncode == 0 and out.stdout.startswith("softhand ")
    out = run("--help")
    assert out.returncode == 0 and "verbs:" in out.stdout


def test_unknown_verb_is_one_line_exit_2(capsys):
    assert main(["frobnicate"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "frobnicate" in err


def test_ctrl_c_while_a_verb_imports_its_libraries_is_one_line(monkeypatch, capsys):
    from softhand.studies.cli import main as front

    def importing(verb):
        raise KeyboardInterrupt

    monkeypatch.setattr(front, "_verb_module", importing)
    assert main(["curve", "--theta-deg", "10"]) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "interrupted" in err
