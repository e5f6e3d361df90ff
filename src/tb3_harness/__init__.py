"""One harness for the tools (demo, bench, soak) and every test tier: child
processes and masters (processes), the tutorial run and recorded (tutorial,
report), a TCPROS reader that costs nothing (tcpros_reader), and /proc
measurements (measure)."""
