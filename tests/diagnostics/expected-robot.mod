# Statements must live inside a robot block.
chain H1 - L4(port=45deg) - L1   # expect: error[expected-robot] expected 'robot NAME {', found 'chain'
