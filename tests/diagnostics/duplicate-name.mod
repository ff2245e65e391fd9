robot cellarm {
    chain H1 - H4(pivot=-90deg) - L3(port=45deg)
    target p1 at (0.3, 0, 0.25) m
    target p1 at (-0.24, -0.23, 0.585) m   # expect: error[duplicate-name] 'p1' is already defined in robot 'cellarm'
}
