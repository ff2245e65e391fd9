robot farm {
    chain H1 - H4(twist=45deg) - L4   # expect: error[unknown-parameter] unknown parameter 'twist'
}
