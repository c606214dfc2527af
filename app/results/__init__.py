"""What a run leaves behind: its folder, files, Fig. 6 plots and replay."""
