design cell {
    target a at (0.3, 0, 0.2) m
    links 100 mm to 300 mm step 0 mm   # expect: error[design-bound] the link step must be positive
}
