robot cellarm {
    chain H1 - L4(port=45deg) - L1
    obstacle shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.25) m   # expect: error[expected-statement] expected a statement, found 'obstacle'
}
