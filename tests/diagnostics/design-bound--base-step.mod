design cell {
    target plant at (0.35, 0, 0.20) m
    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 0 mm   # expect: error[design-bound] the base step must be at least 1 mm
}
