robot farm {
    chain H1 - H4(pivot -90deg) - L4   # expect: error[missing-equals] expected '=' after parameter name, found '-90'
}
