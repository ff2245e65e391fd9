robot farm {
    chain H1 - H4(port=1e307rad) - L4   # expect: error[out-of-range] 'port' = 1e+307 rad is out of range (at most 1e+06 rad)
}
