robot farm {
    chain H1 - L4(port=45deg) - L1
}

robot farm {   # expect: error[duplicate-robot] robot 'farm' is defined twice
    chain H1 - H4 - L1
}
