from seisrack.cli import main

raise SystemExit(main())
