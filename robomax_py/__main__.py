from robomax_py.cli import main

main()
