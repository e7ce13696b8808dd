"""The commands, one module each; main.py puts them in the `stablepush` group."""
