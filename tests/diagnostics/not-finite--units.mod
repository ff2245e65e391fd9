design cell {
    target a at (0.3, 0, 0.2) m
    units 1 to 1e400   # expect: error[not-finite] the largest chain must be a finite number
}
