from robomax_py.app.cli import main

main()
