design cell {   # expect: error[design-no-targets] design 'cell' has no targets: nothing to design the arm for
    box table size (1, 1, 0.02) m at (0, 0, -0.01) m
    units 2 to 3
}
