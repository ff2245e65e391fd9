robot cellarm {
    chain H1 - L4(port=45deg) - L1
    box shelf size (0.6, 0.4, 0.02) meters at (0.3, 0, 0.25) m   # expect: error[unknown-unit-of-measure] unknown unit 'meters'
}
