"""``shell`` in a user's script runs as plain LIGGGHTS runs it (``shell mkdir post`` is in many
users' scripts and in Debian's tutorials; the host used to refuse it): once, in the script's
folder, and never in the forked copy that tries a script's commands first."""
import pytest
from test_script_checks import header, run, toml
from test_script_time import native

pytestmark = pytest.mark.engines

SHELL = """shell mkdir post
shell echo one line >> shell.txt
fix out all print 100 "${t}" file post/t.txt screen no
variable t equal step
run 300
shell echo after the run >> shell.txt
run 100
"""


def test_shell_commands_run_once_as_in_plain_liggghts(tmp_path):
    """The folder a 'fix print' writes into made by 'shell mkdir', and each 'shell echo ... >>'
    appending one line, as in 'liggghts -in': the same shell.txt and post/t.txt."""
    script = header() + SHELL
    plain = native(tmp_path, script)
    r, s = run(tmp_path, script, toml())
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert s["steps"] == 400
    assert (tmp_path / "shell.txt").read_text() == (plain / "shell.txt").read_text() == "one line\nafter the run\n"
    assert (tmp_path / "post" / "t.txt").read_text() == (plain / "post" / "t.txt").read_text()
