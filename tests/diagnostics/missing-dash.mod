robot farm {
    chain H1 - H4(pivot=-90deg) L4(port=45deg)   # expect: error[missing-dash] expected '-' between units in a chain, found 'L4'
}
