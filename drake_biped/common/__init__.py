"""What the experiments share and the command line uses: the Dask executor and its local cluster (`executor`), run
logs and progress bars (`progress`), the shared options and the bounds on what a run is given (`options`), and the
reading of learning records (`learning_record`). No experiment imports another; what two of them need lives here."""
