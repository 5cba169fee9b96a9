from seisrack.cli import main

# guarded: a process pool started with "spawn" (Dask's nannies) imports the main module again
if __name__ == "__main__":
    raise SystemExit(main())
