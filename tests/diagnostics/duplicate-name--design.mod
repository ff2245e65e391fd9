design cell {
    target a at (0.3, 0, 0.2) m
    target a at (0.2, 0.1, 0.3) m   # expect: error[duplicate-name] 'a' is already defined in design 'cell'
}
