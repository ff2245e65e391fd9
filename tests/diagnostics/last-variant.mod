robot farm {
    chain H1 - H4(port=45deg)   # expect: error[last-variant]
}
