robot farm {
    chain H1 - H4(port=45deg)   # expect: error[last-variant] the last unit is H4; the paper's rule 1 fixes link n as L
}
