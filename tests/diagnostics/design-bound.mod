design cell {
    target a at (0.3, 0, 0.2) m
    units 3 to 2   # expect: error[design-bound] `units 3 to 2` is an empty range
}
