robot farm {
    chain H1 - H4(port=1e307rad) - L4   # expect: error[out-of-range]
}
