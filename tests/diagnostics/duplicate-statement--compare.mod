design cell {
    target plant at (0.35, 0, 0.20) m
    compare with chain H1 - L4(port=45deg) - L3
    compare with chain H1 - L3   # expect: error[duplicate-statement] 'compare with' is given twice in design 'cell'
}
