robot farm {
    chain H1 - X4(port=45deg) - L1   # expect: error[unknown-module] unknown module unit 'X4'
}
