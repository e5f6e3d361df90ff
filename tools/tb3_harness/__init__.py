"""One harness for the tools (demo, bench, soak) and every test tier: child
processes and masters (processes), the tutorial run and recorded (tutorial,
report), a TCPROS reader that costs nothing (tcpros_reader), and /proc
measurements (measure); the drives and the small closed loops the
navigation cores' tests run on (drives, nav_sim, explore_sim). Not installed:
tools/ is on the path of make's commands and the tests (pytest.ini), not of
a user's shell."""
from pathlib import Path

#: The repository's root: the tb3_sim_nav package, with packages/ beside its own folders.
ROOT = Path(__file__).resolve().parents[2]
