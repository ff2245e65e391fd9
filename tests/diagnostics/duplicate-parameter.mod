robot farm {
    chain H1 - H4(port=45deg, pivot=15deg, port=90deg) - L4   # expect: error[duplicate-parameter] parameter 'port' is given twice
}
