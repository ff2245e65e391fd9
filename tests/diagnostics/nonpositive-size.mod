robot cellarm {
    chain H1 - H4(pivot=-90deg) - L3(port=45deg)
    sphere ball radius 0 m at (0.3, 0, 0.25) m   # expect: error[nonpositive-size] every dimension of sphere 'ball' must be positive, got 0 m
}
