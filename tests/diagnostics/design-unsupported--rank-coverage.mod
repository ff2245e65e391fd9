# `rank coverage`: every design modc returns reaches every point, so there is nothing to rank yet
design farm {
    target plant at (0.30, 0.10, 0.25) m
    target tray at (0.25, -0.15, 0.30) m
    units 2 to 3
    task serve { visit plant, tray }
    rank coverage, cycle_time   # expect: warning[design-unsupported] `rank coverage` is parsed but not searched yet by modc design
}
