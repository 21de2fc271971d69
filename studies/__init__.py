"""What connects the layers: FEM studies, comparisons, the batch runner and the CLI."""
