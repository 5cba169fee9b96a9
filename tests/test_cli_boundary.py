"""The one boundary where every command meets the operating system (issue 23, class 1).

Disk full, read-only or missing folders, permissions, memory, networks, Ctrl-C and errors that
escape a library become the one-paragraph error (exit 2; 130 for Ctrl-C) naming the path and
what to do, or the JSON error object under ``--json``; ``seisrack ... | head`` ends quietly;
writers leave no temporary or half-written file behind.

The operating-system failures are raised by monkeypatching (the tests run as root, for whom
permissions do not apply, and cannot fill a disk); the pipe is a real one.
"""

from __future__ import annotations

import errno
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rack_inputs import PAPER_RACK
from seisrack import atomic
from seisrack.cli import main

REPO = Path(__file__).resolve().parents[1]


def _raise(exc: BaseException):
    def f(*_a, **_k):
        raise exc
    return f


def _text_error(capsys, argv: list[str], code: int = 2) -> str:
    assert main(argv) == code
    cap = capsys.readouterr()
    assert cap.out == "" and "Traceback" not in cap.err
    assert cap.err.startswith("seisrack: error: ") and cap.err.count("\n") == 1
    return cap.err


def _json_error(capsys, argv: list[str], code: int = 2) -> dict:
    assert main([*argv, "--json"]) == code
    cap = capsys.readouterr()
    assert cap.err == ""
    obj = json.loads(cap.out)
    assert set(obj) == {"error"} and set(obj["error"]) == {"field", "value", "allowed",
                                                          "message"}
    return obj["error"]


@pytest.mark.parametrize(("err", "words"), [
    (errno.ENOSPC, "no space left"), (errno.EROFS, "read-only"),
    (errno.EACCES, "permission denied"), (errno.ENOENT, "not found"),
    (errno.EISDIR, "folder"), (errno.EIO, "input/output"),
])
def test_os_errors_name_the_path(monkeypatch, capsys, tmp_path, err, words):
    path = str(tmp_path / "out" / "modes.png")
    monkeypatch.setattr("seisrack.fe.modal.modal_analysis",
                        _raise(OSError(err, "os says no", path)))
    text = _text_error(capsys, ["modal", str(PAPER_RACK)])
    assert words in text and path in text
    obj = _json_error(capsys, ["modal", str(PAPER_RACK)])
    assert obj["value"] == path and words in obj["message"] and obj["allowed"]


def test_memory_error(monkeypatch, capsys):
    monkeypatch.setattr("seisrack.fe.modal.modal_analysis", _raise(MemoryError()))
    text = _text_error(capsys, ["modal", str(PAPER_RACK)])
    assert "out of memory" in text and "smaller" in text
    assert _json_error(capsys, ["modal", str(PAPER_RACK)])["field"] == "memory"


def test_network_error(monkeypatch, capsys):
    monkeypatch.setattr("seisrack.fe.modal.modal_analysis",
                        _raise(ConnectionRefusedError(111, "Connection refused")))
    text = _text_error(capsys, ["modal", str(PAPER_RACK)])
    assert "network error" in text and "SCHEDULER-HOST" in text


def test_internal_error_is_one_paragraph(monkeypatch, capsys):
    class ArrowInvalid(ValueError):  # what pyarrow raises on a foreign file, for example
        pass

    monkeypatch.setattr("seisrack.fe.modal.modal_analysis",
                        _raise(ArrowInvalid("Parquet magic bytes not found\nsecond line")))
    text = _text_error(capsys, ["modal", str(PAPER_RACK)])
    assert "internal error" in text and "ArrowInvalid" in text and "second line" not in text
    assert "SEISRACK_TRACEBACK=1" in text
    monkeypatch.setenv("SEISRACK_TRACEBACK", "1")
    assert main(["modal", str(PAPER_RACK)]) == 2
    assert "Traceback" in capsys.readouterr().err  # asked for: the traceback for a report


def test_ctrl_c(monkeypatch, capsys):
    monkeypatch.setattr("seisrack.fe.modal.modal_analysis", _raise(KeyboardInterrupt()))
    text = _text_error(capsys, ["modal", str(PAPER_RACK)], code=130)
    assert "interrupted" in text
    assert "interrupted" in _json_error(capsys, ["modal", str(PAPER_RACK)], code=130)["message"]


def test_broken_pipe_is_quiet(tmp_path):
    """``seisrack ... | head``: exit 0, nothing on stderr (a real pipe, larger than its
    buffer, closed by the reader after a few bytes)."""
    rec = tmp_path / "rec.csv"
    np.savetxt(rec, np.column_stack([np.arange(200) * 0.01, np.sin(np.arange(200))]),
               delimiter=",", header="time_s,accel_m_s2", comments="")
    periods = ",".join(f"{t:.4f}" for t in np.linspace(0.02, 4.0, 6000))
    cmd = [sys.executable, "-m", "seisrack", "motion", "spectrum", str(rec), "--periods",
           periods]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    p.stdout.read(20)
    p.stdout.close()  # the reader goes away, as `head -c 20` does
    err = p.stderr.read().decode()
    assert p.wait(timeout=120) == 0
    assert err == "", err


def test_atomic_write_leaves_nothing_on_failure(tmp_path):
    target = tmp_path / "result.csv"
    target.write_text("what the user had\n")

    def half_then_full(p: Path) -> None:
        p.write_text("half of a fi")
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError) as exc:
        atomic.atomic_write(target, half_then_full)
    assert exc.value.errno == errno.ENOSPC and exc.value.filename == str(target)
    assert target.read_text() == "what the user had\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.csv"]
    with pytest.raises(KeyboardInterrupt):
        atomic.atomic_write(target, lambda p: (p.write_text("x"), _raise(KeyboardInterrupt())()))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["result.csv"]


def test_disk_full_during_export(monkeypatch, capsys, tmp_path):
    """A full disk while the script is written: the error names the file, and neither the
    script nor a temporary file is left in the folder."""
    out = tmp_path / "rack_ops.py"
    real = Path.write_text

    def full(self, data, *a, **k):  # noqa: ANN001
        real(self, data[: len(data) // 2], *a, **k)
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(Path, "write_text", full)
    text = _text_error(capsys, ["export", "opensees", str(PAPER_RACK), "--out", str(out)])
    assert "no space left" in text and str(out) in text
    assert list(tmp_path.iterdir()) == []


def test_unknown_figure_format_is_an_input_error(capsys, tmp_path):
    text = _text_error(capsys, ["modal", str(PAPER_RACK), "--plot", str(tmp_path / "m.xyz")])
    assert "m.xyz" in text and ".png" in text
    assert list(tmp_path.iterdir()) == []
