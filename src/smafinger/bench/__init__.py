"""The controller bench: every controller x strategy on the paper's moves, its full cycle, a
staircase and sine tracking, on the joint and on the linear actuator (``smafinger
bench-controllers``), and gain tuning (``smafinger tune``). See docs/controllers.md."""
