# `base within … yaw` with a region: an axis-aligned region box cannot turn with the base
# expect-line 7: warning[design-unsupported] `base within … yaw` with a region is parsed but not searched yet by modc design
design farm {
    target plant at (0.30, 0.10, 0.25) m
    region tray box size (0.10, 0.05, 0) m at (0.3, -0.2, 0.2) m grid 2 x 2 x 1
    units 2 to 3
    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm yaw 0 to 90 deg step 45 deg
}
