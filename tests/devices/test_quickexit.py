"""``ignjax.devices.quickexit.exit_now``: what a command's process still does when it ends without Python's teardown."""

import subprocess
import sys
import textwrap


def _run(tmp_path, status: str):
    script = textwrap.dedent(f"""
        import atexit, pathlib, sys, threading, time
        from ignjax.devices.quickexit import exit_now
        out = pathlib.Path({str(tmp_path)!r})
        atexit.register(lambda: (out / "atexit").write_text("ran"))
        def late():
            time.sleep(0.3)
            (out / "thread").write_text("joined")
        threading.Thread(target=late).start()
        sys.stdout.write("buffered, no newline")
        exit_now({status})
        (out / "after").write_text("never")
    """)
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)


def test_exit_now_joins_threads_runs_handlers_flushes_and_keeps_the_status(tmp_path):
    p = _run(tmp_path, "3")
    assert p.returncode == 3, p.stderr
    assert p.stdout == "buffered, no newline"
    assert (tmp_path / "thread").read_text() == "joined"  # a non-daemon thread finishes, as at a normal exit
    assert (tmp_path / "atexit").read_text() == "ran"
    assert not (tmp_path / "after").exists()


def test_exit_now_takes_none_and_a_message_as_sys_exit_does(tmp_path):
    assert _run(tmp_path, "None").returncode == 0
    p = _run(tmp_path, "'no episodes'")
    assert p.returncode == 1 and "no episodes" in p.stderr
